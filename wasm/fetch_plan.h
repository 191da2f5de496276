// What the viewer fetches of a dataset with a patch hierarchy (FORMAT.md §1.1): by default the
// nodes the current view needs (those whose range of the isovalue's field holds the isovalue,
// and with the slice on those its plane crosses), or every node. Their chunks come most
// important first: a node's measured field error times what its region covers on screen,
// regions out of view last, each after its parent. Once the nodes the isovalue needs are
// applied, the surface is the full-resolution one exactly.
// A dataset without nodes (format 1) is one sequence: every chunk, in order.
#pragma once
#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

#include "manifest.h"
#include "mesh.h"

namespace tetstream::viewer {

struct ViewerState;

enum class FetchMode : uint8_t { Needed, Everything };

struct FetchPlan {
  FetchMode mode = FetchMode::Needed;
  // Bumped whenever what is needed may have changed (isovalue, field, slice, mode, a node given
  // up) or, while streaming, its order (the camera: platform.cpp): the page asks for the plan
  // again (docs/js-api.md).
  uint32_t version = 0;
  std::vector<uint8_t> needed;                  // per node: the view needs it (with its ancestors)
  std::vector<uint8_t> broken;                  // per node: one of its chunks could not be had (its subtree is skipped)
  uint32_t missing = 0;                         // chunks of needed, unbroken nodes not received yet
  std::vector<std::vector<uint32_t>> children;  // per node
  // What a region covers on screen (0: out of view), from the camera; null: every region alike.
  std::function<double(const Bounds&)> screenWeight;
};

// Sets up the plan for a newly opened manifest.
void resetPlan(ViewerState& s);
// Recomputes which nodes are needed (and the missing count); bumps the version.
void replan(ViewerState& s);
// A chunk was received: the missing count follows.
void notePlannedChunk(ViewerState& s, uint32_t index);
// The chunks to fetch next, in order, none received yet; at most `limit`.
std::vector<uint32_t> plannedChunks(const ViewerState& s, uint32_t limit);
// A chunk that cannot be had: its node and everything below it are left out from now on.
void giveUpChunk(ViewerState& s, uint32_t index);

// Whether the surface shown is the full-resolution isosurface of the current field and value:
// every node the isovalue needs received and applied, the level at the newest.
bool exactSurface(const ViewerState& s);
// Nodes whose every chunk is received.
uint32_t nodesLoaded(const ViewerState& s);
// Compressed bytes of the chunks the current view needs (received or not), base included.
uint64_t neededBytes(const ViewerState& s);
// Vertices and tets of the mesh once every node the view needs is applied.
std::pair<uint32_t, uint32_t> neededCounts(const ViewerState& s);

}  // namespace tetstream::viewer
