// Memory for a dataset of regions (FORMAT.md §1.1) kept within the budget (viewer_memory.h) as
// the view changes: the regions a new isovalue or slice needs are fetched only as far as they
// fit, and regions the view no longer needs are given back (their splits undone, their chunks
// forgotten: Dataset's forgetNode) to make room, the latest applied first, since undoing them
// costs least. Without a patch hierarchy the budget is a count of chunks (openManifest).
//
// Eviction runs inside the level machinery: the nodes to forget cap the level at the first of
// their splits (levelCap), advance() undoes down to there a slice at a time, and forgetEvicted()
// then drops them and lifts the cap; the level climbs again over the splits that came after.
#pragma once
#include <cstdint>
#include <vector>

#include "viewer_memory.h"

namespace tetstream::viewer {

struct ViewerState;

struct Eviction {
  std::vector<uint32_t> nodes;            // to forget, in order (each without a received child then)
  uint32_t cap = ~0u;                     // the level may not pass this while `nodes` wait
  std::vector<uint32_t> forgottenChunks;  // chunk indices given back since the page last took them
  uint32_t nodesForgotten = 0;            // since the dataset was opened
  bool memoryFull = false;                // the view needs chunks that do not fit, with nothing left to give back
};

// Whether the dataset's memory is managed by regions: a patch hierarchy and a memory limit.
bool budgetedByRegions(const ViewerState& s);

// The level advance() moves toward: the target, at most what was received and the eviction's cap.
uint32_t levelCap(const ViewerState& s);

// What the chunks in hand bring once the nodes being given back are gone: what the memory limit
// bounds (the nodes' splits are being undone, and the level cannot grow past them meanwhile).
LevelCounts keptCounts(const ViewerState& s);

// The chunks to fetch next, most important first: the plan (fetch_plan.h) as far as it fits in
// memory once the nodes being given back are gone; without regions, the chunks still allowed.
std::vector<uint32_t> chunksToFetch(const ViewerState& s);

// After the plan or the chunks in hand changed: chooses the nodes to give back (none when what
// the view needs fits), sets the cap and memoryFull.
void planEviction(ViewerState& s);

// Called by advance() once the level is at or below the cap: forgets the chosen nodes and lifts
// the cap. True when it did.
bool forgetEvicted(ViewerState& s);

}  // namespace tetstream::viewer
