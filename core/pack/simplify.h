// Tetrahedral mesh simplification by half-edge collapses hec(p_i → p_j) (paper §3).
//
// Every half-edge sits in a priority queue keyed by its cost (both directions; they differ):
//   cost = sqrt(n)·(w_g·E_g + w_f·E_f) + w_s·E_s, each term dimensionless, where n measures
//   what i and j stand for together: the larger of their count of input vertices and their
//   input volume over an interior vertex's mean volume (sqrt(n)·error approximates the root of the
//   summed squared error there, paper eq. 5: what a collapse adds to the RMS at the input's
//   vertices, or to the field's volume error, which isosurfaces show; see boundTerms()):
//   E_g  geometric error, paper eq. (3)-(4): boundary plane quadrics (area weighted, summed on
//        collapse) evaluated at p_j, as an RMS distance divided by the bounding-box diagonal.
//        Zero for interior vertices, whose collapse does not move the boundary.
//   E_f  field error, paper eq. (6) plus a region term, both divided by the field range:
//        |S(p_i) − S'(p_i)|, where S' interpolates the coarse field at p_i inside the tets around
//        p_j after the collapse (the paper's local estimate), plus the RMS deviation of (p_j, s_j)
//        from the linear fields of all original tets that i and j now stand for, kept as
//        volume-weighted 4D field quadrics summed on collapse (Garland & Heckbert's attribute
//        quadrics; our stand-in for eq. (5)'s integral over the original vertices of the region).
//        s_j is the value j takes after the collapse (fitValues below).
//   E_s  shape error, paper §3.3: the measure κ(S) − 3 normalised as (κ − 3)/κ = 1 − 3/κ, in
//        [0, 1), averaged over the tets around p_j after the collapse (0: all equilateral).
//        The paper's unbounded κ − 3 lets the shape term outweigh the field wherever a mesh is
//        anisotropic (graded CFD grids, docs/design-notes.md).
// The whole cost is then divided by sqrt(r), r the number of tets the collapse removes (the
// tets around the edge): a level is as large as its tets (the base's bytes, the viewer's work
// and the benchmarks' levels go by tets), so a collapse that removes six tets may err more
// than one that removes three and still go first. The root, not r itself: a split's bytes go
// by its vertex as well as by its tets, so r itself over-rewards collapses of many tets and
// gives a higher error at the same bytes received.
// Defaults (100, 1, 0.005) keep the boundary first, then the field; tet shape is a
// tie-breaker; all terms are scale free, so they work for any mesh size and field range.
// A larger shape weight gives better tets and a lower error at the coarsest levels, but a higher
// one at finer levels; 0.005 balances the two (docs/design-notes.md).
//
// Legality, checked for every collapse (paper §3.2 and Staadt & Gross / Dey et al.):
//   - a boundary vertex may only move along a boundary edge;
//   - the link condition Lk(i) ∩ Lk(j) = Lk(ij), with the boundary coned to a virtual vertex,
//     so the mesh and its boundary keep their topology and stay manifold;
//   - no tet that moves from p_i to p_j may become inverted or flat (eq. 1, relative tolerance)
//     or fall below the minimum quality 3/κ ≥ minQuality (where the star already has worse
//     tets, as boundary layers of CFD grids do: below the worst of them).
// Consequences: no collapse creates an inverted or flat tet; flat tets of the input only ever
// disappear (when they contain the collapsed edge) or become proper.
//
// Order: one priority queue of vertices by the cost of their cheapest out-edge, updated lazily.
// Meshes of 2·leafVertices or more are first simplified in a tree of regions (simplify_tree.cpp):
// the vertices are bisected recursively into 2^depth leaves; level by level from the leaves up,
// each region collapses only vertices whose whole neighbourhood is its own, up to a cost shared
// by its level, on one of two threads; what the regions had to leave (the cuts between them) is
// inside the region above. The one queue of the whole mesh, the root, takes the last collapses.
// Each region's collapses are one section of the log, so its splits depend on those of the
// regions above it and on no other (FORMAT.md §1.1). A fitted value is kept within the range of
// the input field over the region that fitted it: a region whose range misses an isovalue then
// shows no surface at any level. On such meshes a vertex whose cost rose by at most 10% since
// it was queued is collapsed without going back into the queue.
//
// The result is a log of collapses for the encoder (split_encode.h); the simplifier knows
// nothing of the file format. Deterministic: same input and options, same log, whatever the
// number of threads.
#pragma once
#include <bit>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "adjacency.h"
#include "mesh.h"
#include "pack/collapse_log.h"
#include "pack/quadric.h"
#include "status.h"

namespace tetstream {

// Packing on several processes (pack/distributed.h) simplifies the mesh as parts: each a region
// of the input (its own vertices, "owned") with a halo (every other vertex of a tet that has an
// owned vertex, and those tets), first a rank's region from the input, then, level by level up
// the tree of ranks, two finished parts merged. Only owned vertices whose tets all have four
// owned vertices are ever collapsed (the halo is another part's, left as it is), so parts are
// independent. What collapses accumulate per vertex (below) goes from one part to the next, so
// costs and fitted values come out as if one process had held the whole mesh.
struct CarriedVertexState {
  std::vector<float> fit;                // the steering field's value now (fitted)
  std::vector<uint32_t> represented;     // input vertices each stands for
  std::vector<uint8_t> boundary;         // on the input's boundary (its boundary quadric counts)
  std::vector<Quadric> boundaryQuadric;  // per vertex (zero when not on the boundary)
  std::vector<FieldQuadric> fieldQuadric;
  // The range each fitted value keeps to: the input field's range over the region whose collapse
  // fitted it last (a refit of the base keeps to it, so a region left out still shows no surface
  // of a value outside its range; FORMAT.md §1.1).
  std::vector<Range> fitRange;
};

struct SimplifyPart {
  const std::vector<uint8_t>* owned = nullptr;  // per vertex of the part's mesh: 1 owned, 0 halo
  // The state of the previous level, per vertex of the part's mesh (null: computed from the
  // input, as simplifyMesh does). The part's mesh then holds the current tets; its fields are
  // the input's samples.
  const CarriedVertexState* carried = nullptr;
  // The whole mesh's normalisers (a part's own would differ from rank to rank): the steering
  // field's range, the bounding box diagonal, the mean volume of an interior vertex.
  double fieldMin = 0, fieldMax = 0, diagonal = 1, meanVertexVolume = 1;
  // The range fitted values of the part's top node keep to (the input field over its region).
  double topMin = 0, topMax = 0;
  // true: the part's top node collapses like a region of the tree (inner vertices, up to the
  // level's cost τ) and stops; false: it is the root, the queue of the whole mesh, which goes on
  // to the target (then nothing may be halo).
  bool topIsRegion = false;
  // The whole input's vertex count: the queue's slack (tryCollapse) depends on the mesh's size,
  // and every part should use the whole mesh's (0: this part's).
  uint64_t inputVertices = 0;
};
// How a part is simplified (simplifyMesh with SimplifyOptions::part):
//   - an owned vertex is collapsed, and is a collapse target, only when every alive tet around
//     it has four owned vertices (and, in the part's tree, lies in its region); halo vertices
//     never are;
//   - the part's tree bisects its owned vertices alone (RegionTree::leafOf is ~0u for halo
//     vertices); node 1 is the part's top; with topIsRegion it collapses up to its level's cost
//     τ and its collapses are the section of node 1;
//   - targetVertices and targetTets are the part's share, compared with its owned alive vertices
//     (and its tets);
//   - values are not refitted at the end (refitValues is ignored): SimplifyResult::values are the
//     fitted values;
//   - SimplifyResult::carried covers the vertices left alive, in vertex order (partAfter, part.h,
//     takes it with them). A halo vertex's state is what this part had of it (its boundary may be
//     the part's cut): only its owner's counts.
// Deterministic as the whole mesh's simplification: the same for any number of threads.

// The whole mesh's normalisers for SimplifyPart (fieldMin, fieldMax, diagonal, meanVertexVolume
// and inputVertices) as simplifyMesh computes them for `mesh` itself, with topMin/topMax the
// field's range: for a caller that holds the whole mesh.
SimplifyPart wholeMeshPart(const TetMesh& mesh, int field);

struct SimplifyOptions {
  double weightGeometry = 100.0, weightField = 1.0, weightShape = 0.005;
  uint32_t targetVertices = 0;  // stop at this many vertices (0: as far as legal collapses go)
  uint32_t targetTets = 0;      // ...or at this many tets, whichever comes first
  // Stop when the collapse next in line would leave a field error E_f (relative to the field's
  // range) above this.
  double maxError = std::numeric_limits<double>::infinity();
  int field = 0;             // index of the field that steers the field error
  double minQuality = 0.02;  // 3/κ of every tet a collapse changes must stay at or above this
                             // (or at the worst 3/κ of the star before it, when that is lower)
  // After each collapse the kept vertex takes the value of the steering field that fits the
  // original field over everything it stands for (field quadric minimum at p_j); the log keeps
  // the values before, so splits restore them exactly. Off: every vertex keeps its sample.
  bool fitValues = true;
  // With fitValues, at the end the values of the vertices that stand for others are fitted again,
  // all together, to the input field at every input vertex (least squares; simplify_refit.cpp).
  bool refitValues = true;
  std::function<void(uint32_t done, uint32_t planned)> progress;  // called now and then
  // Keep in the log what each split reads (CollapseLog::star), for StreamOptions::orderSplits.
  bool recordReadSets = false;
  // Threads (1 or 2; the result is the same either way): the regions of a level share them, and the
  // one queue evaluates its next entries on both for meshes of at least parallelMinVertices
  // vertices (below that, starting rounds costs more than it saves).
  int threads = 2;
  uint32_t parallelMinVertices = 20000;
  // Largest leaf of the tree of regions, in vertices; meshes of fewer than twice this are one
  // region (0: always). The result depends on this, not on `threads`. Smaller leaves let a
  // viewer fetch fewer bytes for a given isovalue, in more and smaller files: over HTTP/1.1 (six
  // connections) at 10 Mbit/s and 50 ms, files of leaves of 1,024 vertices (~5 KB) leave the
  // link two-thirds idle, and 2,048 reached the exact surface of Harmonic 64³ a fifth sooner
  // with 3% more bytes (docs/design-notes.md).
  uint32_t leafVertices = 2048;
  // A part of a mesh packed on several processes (SimplifyPart); null: the whole mesh.
  const SimplifyPart* part = nullptr;
};

// The tree of regions (simplify.h): a perfect binary tree in heap numbering, the root node 1,
// node n's children 2n and 2n + 1, leaf k node 2^depth + k.
struct RegionTree {
  uint32_t depth = 0;            // levels below the root (0: the root alone)
  std::vector<uint32_t> leafOf;  // per input vertex: its leaf 0 .. 2^depth − 1 (empty at depth 0)
  // A tet lies in the first leaf (lowest number) that holds one of its vertices: (leaf, vertex)
  // for each vertex of a leaf's input tets that lies in a later leaf, sorted. A leaf's range and
  // bounds hold these too, as its tets reach them.
  std::vector<std::pair<uint32_t, uint32_t>> rim;
  // The log in sections, each the collapses of one node: section s is
  // [sectionEnd[s − 1] (0 for s = 0), sectionEnd[s]), made by node sectionNode[s]. Leaves
  // first, the root last; nodes without collapses have no section.
  std::vector<uint32_t> sectionNode, sectionEnd;

  uint32_t nodes() const { return 2u << depth; }  // one past the largest node id
  // The node at `level` (0: leaves) above input vertex v.
  uint32_t nodeOf(uint32_t v, uint32_t level) const {
    return depth == 0 ? 1u : (1u << (depth - level)) + (leafOf[v] >> level);
  }
  // The level of node n (0: leaves, depth: the root): n lies in [2^(depth − level), 2^(depth − level + 1)).
  uint32_t levelOf(uint32_t node) const { return depth - uint32_t(std::bit_width(node) - 1); }
};

struct SimplifyResult {
  CollapseLog log;
  std::vector<uint32_t> tets;     // 4 per original tet, current vertices (valid where tetAlive)
  std::vector<uint8_t> tetAlive;  // 1 per original tet
  std::vector<uint8_t> vertexAlive;
  std::vector<float> values;            // the steering field per vertex at the end (fitted values)
  int valuesField = -1;                 // the index of that field in the mesh
  uint32_t vertices = 0, tetCount = 0;  // counts of the base mesh
  uint32_t flatTetsRemoved = 0;         // input tets with zero volume that the collapses removed
  uint32_t flatTetsLeft = 0;
  uint64_t costEvaluations = 0, rejectedByLink = 0;
  uint64_t queuePops = 0, requeued = 0;  // pops of current entries, and those pushed back costlier
  uint32_t regionCollapses = 0;          // collapses made below the root, on two threads at once
  RegionTree tree;
  CarriedVertexState carried;  // with SimplifyOptions::part: the state at the end, per alive vertex
  // "target reached", "no legal collapse left", "error bound reached", or (a part's top node
  // as a region, SimplifyPart::topIsRegion) "level cost reached".
  std::string stopReason;
};

// Why a single collapse is or is not allowed (for tests and diagnostics).
enum class CollapseVerdict { Legal, BoundaryRule, Inverted, Flat, LowQuality, LinkCondition, NotAnEdge };
const char* collapseVerdictName(CollapseVerdict v);

// Checks hec(i → j) on `mesh` as the simplifier would before collapsing it.
CollapseVerdict checkCollapse(const TetMesh& mesh, uint32_t i, uint32_t j, const SimplifyOptions& options = {});

// Simplifies `mesh` (positions already on the packer's quantization grid; tets positively
// oriented or flat). Fails only on a mesh the caller should have validated (asserted).
// `adjacency`, when given, is the face adjacency of `mesh` (buildFaceAdjacency), saving its rebuild.
// `takeTets`, when given, is mesh.tets itself, taken over instead of copied (it is left empty:
// the packer needs them no longer, and a copy is 16 bytes a tet of the peak memory).
Result simplifyMesh(const TetMesh& mesh, const SimplifyOptions& options, SimplifyResult& out,
                    FaceAdjacency* adjacency = nullptr, std::vector<uint32_t>* takeTets = nullptr);

}  // namespace tetstream
