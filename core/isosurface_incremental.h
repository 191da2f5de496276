// The isosurface of a mesh that changes by local edits (vertex splits and their undo), kept up to
// date tet by tet instead of being extracted again (paper §4.3), plus the interval tree that makes
// a full re-extraction at a new isovalue fast (§4.2).
//
// The surface is the one extractIsosurface (isosurface.h) produces on the current mesh, up to
// ordering: the same triangles (same corner positions bit for bit, same winding), the same surface
// vertices (one per cut edge, keyed by its sorted vertex pair, or by the mesh vertex when its value
// equals λ; vertices of triangles dropped as degenerate included), normals equal up to the
// rounding of the area-weighted sums (accumulated here in double).
//
// Renderer-facing arrays (all flat, grown but never shrunk while streaming):
//   positions(): 3 floats per vertex slot, normals(): 3 floats per vertex slot (unit, or 0 for a
//   vertex no triangle uses). Vertex slots have holes: a freed slot keeps stale data and no live
//   triangle refers to it, so the arrays can be drawn as they are (vertexSlotCount() vertices).
//   compact() closes the holes when wanted.
//   colours(): 1 float per vertex slot, the colour field (any point field, optional) interpolated
//   along the vertex's cut edge with the same weights as its position (0 without one).
//   indices(): 3 uint32 per triangle, dense: triangles 0 .. triangleCount()-1 are all live (a
//   removed triangle's slot is refilled with the last one).
// Change tracking for sub-range GPU uploads: changedVertices()/changedTriangles() list the slots
// written since clearChanges() (each once, unordered; triangle slots >= triangleCount() may be
// listed and are to be ignored; listed vertex slots may have been freed since), with their
// bounding ranges; fullUploadNeeded() is set by rebuild() and compact(), after which the lists
// stay empty until clearChanges(). The arrays may have grown past the renderer's buffers:
// compare vertexSlotCount()/triangleCount() with what was allocated.
//
// Contract for updateTets: mesh vertices keep their ids, positions and field values once they
// exist (true for half-edge-collapse splits: p0 stays, p1 is appended); a tet whose corners
// changed is listed; ids >= the new tetCount() are removed tets; ids between the previous and the
// new tetCount() are new tets whether listed or not. An edit that does change a vertex's value
// or position is allowed when every tet around that vertex is listed (its surface vertices are
// then all released before any is created again).
//
// Memory: per tet 4 bytes (record index) + 1 bit (rebuild's ordering bitmap) + the interval
// tree (18-28 bytes); per cut tet a 28-byte record; per triangle 17 bytes; per surface vertex
// about 104 bytes (position, normal, colour, double normal sum, key, counts, hash slots);
// memoryBytes() reports the actual figure.
// Speed: updateTets costs microseconds per split (a dozen changed tets), far below a full
// extraction; rebuild() only visits the cut tets the interval tree returns, at about twice the
// bare marching-tets work on them (the bookkeeping that makes the local updates possible).
// Figures: docs/design-notes.md.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "interval_tree.h"
#include "isosurface.h"
#include "mesh.h"

namespace tetstream {

class IncrementalIsosurface {
 public:
  static constexpr uint32_t kNone = ~uint32_t(0);

  // Forgets the surface and the interval tree (keeps memory). Call when the field or the mesh is
  // replaced by anything other than edits reported through updateTets.
  void reset();

  // Extracts the whole surface at `isovalue` (the isovalue slider). Builds the interval tree when
  // there is none yet (first call, after reset()) or its tet count differs from the mesh's,
  // otherwise only queries it. Precondition (asserted): field.size() == mesh.vertexCount().
  // `colour` (empty, or one value per mesh vertex) is interpolated at each surface vertex.
  void rebuild(const TetMesh& mesh, std::span<const float> field, float isovalue, std::span<const float> colour = {});

  // Recomputes the triangles of the listed tets (T_new and T_moved of a split or its undo, and
  // every tet around p_j when the split changes p_j's value; see the contract above), updates the interval tree for
  // them, releases unused surface vertices and renormalises the touched vertices' normals. No allocation once the
  // arrays are warm. Precondition (asserted): rebuild() was called since the last reset(). `colour` as for rebuild()
  // (the same field every time, or recolour() after switching).
  void updateTets(const TetMesh& mesh, std::span<const float> field, std::span<const uint32_t> changedTets,
                  std::span<const float> colour = {});

  // Another colour field (or none: empty) for the current surface: every live vertex's colour
  // interpolated again along its edge, no geometry touched; sets fullUploadNeeded().
  void recolour(std::span<const float> colour);

  // Renumbers vertex slots densely (no holes); sets fullUploadNeeded().
  void compact();

  // Deferred interval tree, for a mesh that is being refined fast (a level streaming in). The
  // tree covers tets [0, treeCoverage()): rebuild() queries it for those and tests every other
  // tet's interval itself; updateTets keeps it up to date for those only. Keeping it up to date
  // costs about a third of a split's refinement time, which is wasted while
  // hundreds of thousands of splits stream in and the isovalue does not change. By default
  // (deferred off) rebuild() builds the tree over the whole mesh and updateTets keeps it whole.
  // Deferred, rebuild() never builds it at once (on a large mesh that freezes a frame);
  // extendTree() grows it by at most maxTets tets per call, for idle time in short slices, and
  // returns true once it covers the mesh. Tets added by updateTets later are not covered until
  // extendTree() is called again. setTreeDeferred(true) keeps what is covered.
  void setTreeDeferred(bool deferred);
  bool extendTree(const TetMesh& mesh, std::span<const float> field, uint32_t maxTets);
  uint32_t treeCoverage() const { return coverage_; }

  // Sizes the per-tet arrays (the record index and the tree's intervals) for `tets` tets, so
  // that streaming up to that count copies no array (a doubling copy of a 1.5M-tet array takes
  // several ms inside one refinement slice).
  void reserveTets(uint32_t tets);

  // The surface as a compact IsoSurface (vertices in slot order), equal to extractIsosurface's
  // output up to the order of vertices and triangles.
  void toIsoSurface(IsoSurface& out) const;

  float isovalue() const { return isovalue_; }
  std::span<const float> positions() const { return {positions_.data(), 3 * size_t(vertexSlotCount())}; }
  std::span<const float> normals() const { return {normals_.data(), 3 * size_t(vertexSlotCount())}; }
  std::span<const float> colours() const { return {colours_.data(), size_t(vertexSlotCount())}; }
  std::span<const uint32_t> indices() const { return {indices_.data(), 3 * size_t(triangleCount())}; }
  uint32_t vertexSlotCount() const { return uint32_t(vertices_.size()); }
  uint32_t vertexCount() const { return uint32_t(map_.size()); }  // live vertices
  uint32_t triangleCount() const { return triangleCount_; }
  // Sum of triangle areas (double, kept by adding and subtracting each triangle's area).
  double area() const { return area_; }

  bool fullUploadNeeded() const { return fullUpload_; }
  std::span<const uint32_t> changedVertices() const { return changedVertices_; }
  std::span<const uint32_t> changedTriangles() const { return changedTriangles_; }
  // [begin, end) bounding the listed slots; begin == end when none.
  uint32_t changedVertexBegin() const { return changedVertices_.empty() ? 0 : vBegin_; }
  uint32_t changedVertexEnd() const { return changedVertices_.empty() ? 0 : vEnd_; }
  uint32_t changedTriangleBegin() const { return changedTriangles_.empty() ? 0 : tBegin_; }
  uint32_t changedTriangleEnd() const { return changedTriangles_.empty() ? 0 : tEnd_; }
  void clearChanges();

  const IntervalTree& intervalTree() const { return tree_; }
  // Heap bytes in use (vector capacities), tree included.
  size_t memoryBytes() const;
  // Checks internal invariants (tests): reference counts, triangle owners, map, area sum.
  bool validate() const;

 private:
  struct Context;
  void clearSurface();
  void addTet(const Context& c, uint32_t t);
  void removeTet(uint32_t t);
  uint32_t acquireVertex(const Context& c, uint32_t a, uint32_t b);
  void releaseVertex(uint32_t v);
  void addTriangle(uint32_t record, int which, const uint32_t tri[3]);
  void removeTriangle(uint32_t slot);
  void accumulate(const uint32_t tri[3]);
  void touchVertex(uint32_t v);
  void touchTriangle(uint32_t slot);
  void finishNormal(uint32_t v);

  float isovalue_ = 0;
  bool treeBuilt_ = false;  // rebuild() has run since reset()
  bool deferred_ = false;   // see setTreeDeferred
  uint32_t coverage_ = 0;   // the tree holds tets [0, coverage_)
  bool bulk_ = false;       // inside rebuild(): no per-slot change tracking
  IntervalTree tree_;
  FlatMap map_;

  // A tet with a cut case: the up to 4 distinct surface vertices it created or shares
  // (kNone-padded; each counted once in Vertex::refs) and its 0-2 triangle slots (kNone: none).
  struct Record {
    uint32_t vertices[4];
    uint32_t triangles[2];
    uint32_t tet;  // kNone for a free record
  };
  // Bookkeeping of a vertex slot (the renderer's arrays are positions_ and normals_).
  struct Vertex {
    double normalSum[3];  // sum of the live triangles' cross products
    uint64_t key;
    uint32_t refs;       // records using the vertex; 0 for a free slot
    uint32_t triangles;  // live triangles using the vertex
    uint32_t flags;
    float tHigh;  // interpolation weight of the key's larger vertex id (colours)
  };

  std::vector<uint32_t> tetRecord_;  // per tet: its record, or kNone
  std::vector<Record> records_;
  std::vector<uint32_t> freeRecords_;

  // Triangle slots (dense, 0 .. triangleCount_-1 live).
  std::vector<uint32_t> indices_;        // 3 per slot
  std::vector<uint32_t> triangleOwner_;  // record << 1 | which
  std::vector<uint8_t> triangleChanged_;
  uint32_t triangleCount_ = 0;

  // Vertex slots.
  std::vector<float> positions_, normals_;  // 3 per slot
  std::vector<float> colours_;              // 1 per slot
  std::vector<Vertex> vertices_;
  std::vector<uint32_t> freeVertices_;
  double area_ = 0;

  std::vector<uint32_t> touched_;  // vertices whose normal must be renormalised (this update)
  std::vector<uint32_t> changedVertices_, changedTriangles_;
  uint32_t vBegin_ = 0, vEnd_ = 0, tBegin_ = 0, tEnd_ = 0;
  bool fullUpload_ = false;
  std::vector<uint32_t> cutTets_;  // query output, reused
  std::vector<uint64_t> cutBits_;  // one bit per tet, all zero between rebuilds
};

}  // namespace tetstream
