// Orbit camera around the dataset's bounding box, z up (simulation convention).
// Input is in pixels of the viewport it drives; angles in radians; GL clip conventions.
//   left drag: orbit()   wheel: zoom()   right or middle drag: pan()   reset(): frame the box
#pragma once
#include <glm/glm.hpp>

namespace tetstream::viewer {

struct OrbitCamera {
  glm::vec3 boundsMin{-1.f}, boundsMax{1.f};
  glm::vec3 target{0.f};
  float distance = 4.f;
  float yaw = -1.05f;   // eye direction around z, from +x
  float pitch = 0.42f;  // elevation above the xy plane
  float fovY = glm::radians(40.f);

  // Remembers the box and frames it.
  void setBounds(const float min[3], const float max[3], float aspect);
  // Default three-quarter view with the whole box in view at this aspect ratio (width / height).
  void reset(float aspect);

  void orbit(float dxPixels, float dyPixels, float viewportHeight);
  void pan(float dxPixels, float dyPixels, float viewportHeight);
  void zoom(float wheelSteps);  // positive steps move closer

  float radius() const;  // bounding-sphere radius of the box
  glm::vec3 eye() const;
  glm::mat4 view() const;
  glm::mat4 projection(float aspect) const;
};

}  // namespace tetstream::viewer
