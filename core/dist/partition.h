// The tree of ranks and the first parts: every rank's share of the input, cut into one region per
// rank by recursive coordinate bisection computed together (no rank ever holds more than its
// share), then sent where it belongs.
//
// Cuts: a group of ranks splits its points at a plane across the longest side of their bounding
// box, where the lower ranks get their share (half of the points for an even group; a group of
// three gives one third and two thirds). The plane is found by bisecting the coordinate on
// every rank's points at once (32 rounds of counts, one sum each), so all copies of a point (the
// pieces share their interface points) land on the same side. A group of one rank is a leaf:
// that rank's region.
//
// Distribution: a tet goes to every rank that owns one of its vertices, with those vertices'
// positions and values; the owner of a vertex is the rank whose region holds its position. A
// rank's part is then its owned vertices, the tets around them and their other vertices (the
// halo). Copies of a point from several pieces are joined at exactly equal coordinates, keeping
// the values of the lowest rank's copy; copies whose values differ are counted.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "dist/comm.h"
#include "mesh.h"
#include "pack/part.h"

namespace tetstream::dist {

struct RankTree {
  struct Group {
    int first = 0, count = 1;  // ranks [first, first + count)
    int axis = 0;              // the cut (groups of two ranks or more): the low side's points have
    uint64_t cutKey = 0;       // orderKey(coordinate) < cutKey (partition.cpp)
    int low = -1, high = -1;   // child groups (indices), -1 for a single rank
    int parent = -1;
  };
  std::vector<Group> groups;  // groups[0] holds every rank; children after their parents
  // The rank whose region holds point p.
  int ownerOf(const float* p) const;
  // The leaf group of rank r.
  int leafOf(int r) const;
  // The groups, each before its children, the low child's subtree before the high one's: the
  // order of the units in the manifest.
  std::vector<int> preorder() const;
};

// Cuts the points of every rank's `mesh` (vertices used by its tets) into one region per rank.
RankTree cutRegions(Comm& comm, const TetMesh& mesh);

struct DistributionReport {
  uint64_t joinedPoints = 0;            // points that several ranks' pieces held
  std::vector<uint64_t> disagreements;  // per field: joined points whose copies differed
};

// Sends the tets of `mesh` (whose first tet has input id firstTetId) to their owners and builds
// this rank's part. Fields must be the same on every rank (checked before). `mesh` is consumed.
// `cellWeight[f]`, when not empty, says that field f is cell data averaged at the points over
// the cells this rank read, with those cells' volume per point (ReadReport::cellAverages): the
// owner of a point joins its copies' averages by these weights (the average over all its cells,
// as one process reads it) and every rank takes the owner's value.
Result distribute(Comm& comm, TetMesh&& mesh, uint64_t firstTetId, const RankTree& tree,
                  const std::vector<std::vector<double>>& cellWeight, PartMesh& part, DistributionReport& report);

}  // namespace tetstream::dist
