// How large the platform draws a frame's scene (platform.cpp), as a rule with no GL and no
// Emscripten so that it is unit-tested natively.
#pragma once
#include <algorithm>
#include <cmath>

namespace tetstream::viewer {

// On a software GL (SwiftShader & co) a frame drawn while the level refines, or while the user
// drags, draws its scene with at most this many pixels, scaled up to the canvas (as ParaView
// renders while interacting); the first frame after is drawn at full resolution. The GPU
// process's fragment work is what competes with refinement for the CPU.
inline constexpr double kReducedPixels = 640.0 * 400.0;

// The scene's scale for this frame: 1 (full size) unless WebGL renders in software, the level
// is refining or the user interacting (`busy`), and the frame is not a screenshot.
inline float sceneScale(bool softwareGl, bool busy, bool capture, int width, int height) {
  if (!softwareGl || !busy || capture || width <= 0 || height <= 0) return 1.f;
  return float(std::min(1.0, std::sqrt(kReducedPixels / (double(width) * height))));
}

}  // namespace tetstream::viewer
