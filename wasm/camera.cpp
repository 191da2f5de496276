#include "camera.h"

#include <algorithm>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>

namespace tetstream::viewer {
namespace {
constexpr glm::vec3 kUp{0.f, 0.f, 1.f};
constexpr float kMaxPitch = 1.55f;  // just short of the pole, where the up vector degenerates
}  // namespace

void OrbitCamera::setBounds(const float min[3], const float max[3], float aspect) {
  boundsMin = {min[0], min[1], min[2]};
  boundsMax = {max[0], max[1], max[2]};
  reset(aspect);
}

float OrbitCamera::radius() const {
  float r = 0.5f * glm::length(boundsMax - boundsMin);
  return r > 0 ? r : 1.f;
}

void OrbitCamera::reset(float aspect) {
  target = 0.5f * (boundsMin + boundsMax);
  yaw = -1.05f;
  pitch = 0.42f;
  // Fit the bounding sphere into the narrower of the two fields of view.
  float halfY = 0.5f * fovY;
  float halfX = std::atan(std::tan(halfY) * std::max(aspect, 1e-3f));
  float half = std::min(halfX, halfY);
  distance = 1.02f * radius() / std::sin(half);
}

void OrbitCamera::orbit(float dx, float dy, float viewportHeight) {
  float perPixel = 3.14159265f / std::max(viewportHeight, 1.f);  // a full-height drag = 180 degrees
  yaw -= dx * perPixel;
  pitch = std::clamp(pitch + dy * perPixel, -kMaxPitch, kMaxPitch);
}

void OrbitCamera::pan(float dx, float dy, float viewportHeight) {
  // Move the target so the point under the cursor follows it (at the target's depth).
  float worldPerPixel = 2.f * distance * std::tan(0.5f * fovY) / std::max(viewportHeight, 1.f);
  glm::vec3 forward = glm::normalize(target - eye());
  glm::vec3 right = glm::normalize(glm::cross(forward, kUp));
  glm::vec3 up = glm::cross(right, forward);
  target += (-dx * right + dy * up) * worldPerPixel;
}

void OrbitCamera::zoom(float steps) {
  float r = radius();
  distance = std::clamp(distance * std::pow(0.88f, steps), 0.02f * r, 50.f * r);
}

glm::vec3 OrbitCamera::eye() const {
  glm::vec3 dir{std::cos(pitch) * std::cos(yaw), std::cos(pitch) * std::sin(yaw), std::sin(pitch)};
  return target + distance * dir;
}

glm::mat4 OrbitCamera::view() const { return glm::lookAt(eye(), target, kUp); }

glm::mat4 OrbitCamera::projection(float aspect) const {
  // Clip planes hug the bounding sphere (seen from the target) for depth precision.
  float r = radius() + glm::length(target - 0.5f * (boundsMin + boundsMax));
  float zNear = std::max(distance - 1.5f * r, 0.01f * distance);
  float zFar = distance + 1.5f * r;
  return glm::perspective(fovY, std::max(aspect, 1e-3f), zNear, zFar);
}

}  // namespace tetstream::viewer
