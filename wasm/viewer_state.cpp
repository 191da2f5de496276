#include "viewer_state.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <nlohmann/json.hpp>

#include "adjacency.h"

namespace tetstream::viewer {
namespace {

double nowMs() {
  using namespace std::chrono;
  return duration<double, std::milli>(steady_clock::now().time_since_epoch()).count();
}

float middleOf(const Range& r) { return r.min + 0.5f * (r.max - r.min); }

}  // namespace

const char* loadStateName(LoadState s) {
  switch (s) {
    case LoadState::Idle: return "idle";
    case LoadState::Loading: return "loading";
    case LoadState::Streaming: return "streaming";
    case LoadState::Complete: return "complete";
    case LoadState::Error: return "error";
  }
  return "error";
}

Result openManifest(ViewerState& s, std::string_view manifestJson) {
  s.surface.clear();
  s.boundary = {};
  s.surfaceDirty = s.boundaryDirty = true;
  s.boundaryStale = false;
  s.surfaceReady = false;
  s.surfaceArea = 0;
  s.chunksLoaded = s.chunksTotal = 0;
  s.field = -1;
  s.bytesLoaded = manifestJson.size();
  if (Result r = openDataset(s.dataset, manifestJson); !r) {
    s.dataset.manifest = {};
    s.dataset.pm = {};
    s.dataset.chunksApplied = 0;
    s.dataset.bytesApplied = 0;
    failLoad(s, "The dataset description (manifest.json) is not usable: " + r.message);
    return r;
  }
  const Manifest& m = s.dataset.manifest;
  s.chunksTotal = uint32_t(m.chunks.size());
  s.error.clear();
  s.state = LoadState::Loading;
  s.frameRequested = true;
  int f = m.findField(m.isoField);
  if (f < 0 && !m.fields.empty()) f = 0;
  s.field = f;
  if (f >= 0) s.isovalue = middleOf(m.fields[size_t(f)].range);
  return Result::success();
}

Result addChunk(ViewerState& s, uint32_t index, std::span<const uint8_t> bytes) {
  if (s.state != LoadState::Loading && s.state != LoadState::Streaming) {
    Result r = fail(Status::BadArgument, std::string("chunk ") + std::to_string(index) + " arrived while the viewer is " +
                                             loadStateName(s.state));
    if (s.state != LoadState::Error) failLoad(s, r.message);
    return r;
  }
  if (Result r = applyChunk(s.dataset, index, bytes); !r) {
    failLoad(s, "Part " + std::to_string(index + 1) + " of " + std::to_string(s.chunksTotal) +
                    " of the dataset could not be used: " + r.message +
                    (s.chunksLoaded ? ". Showing the last complete level." : "."));
    return r;
  }
  s.chunksLoaded = s.dataset.chunksApplied;
  s.bytesLoaded += bytes.size();
  s.state = s.chunksLoaded == s.chunksTotal ? LoadState::Complete : LoadState::Streaming;
  s.boundaryStale = true;
  extract(s);
  return Result::success();
}

void setIsovalue(ViewerState& s, float value) {
  if (!std::isfinite(value) || value == s.isovalue) return;
  s.isovalue = value;
  extract(s);
}

bool setField(ViewerState& s, int index) {
  const Manifest& m = s.dataset.manifest;
  if (index < 0 || size_t(index) >= m.fields.size()) return false;
  s.field = index;
  s.isovalue = middleOf(m.fields[size_t(index)].range);
  extract(s);
  return true;
}

bool setField(ViewerState& s, std::string_view name) { return setField(s, s.dataset.manifest.findField(name)); }

void failLoad(ViewerState& s, std::string_view message) {
  s.state = LoadState::Error;
  s.error = message.empty() ? "Unknown error." : std::string(message);
}

void extract(ViewerState& s) {
  const TetMesh& mesh = s.dataset.pm.mesh;
  s.surfaceDirty = true;
  int f = s.field >= 0 ? mesh.findField(s.dataset.manifest.fields[size_t(s.field)].name) : -1;
  if (mesh.tetCount() == 0 || f < 0 || mesh.fields[size_t(f)].values.size() != mesh.vertexCount()) {
    s.surface.clear();
    s.surfaceArea = 0;
    s.extractMs = 0;
    return;
  }
  double t0 = nowMs();
  extractIsosurface(mesh, mesh.fields[size_t(f)].values, s.isovalue, s.extractor, s.surface);
  s.extractMs = nowMs() - t0;
  s.surfaceArea = surfaceArea(s.surface);
  s.surfaceReady = true;
}

void updateBoundary(ViewerState& s) {
  if (!s.boundaryStale) return;
  buildBoundary(s.dataset.pm.mesh, s.boundary);
  s.boundaryStale = false;
  s.boundaryDirty = true;
}

void buildBoundary(const TetMesh& mesh, BoundaryMesh& out) {
  out = {};
  if (mesh.tetCount() == 0) return;
  FaceAdjacency adj;
  buildFaceAdjacency(mesh.tets, mesh.vertexCount(), adj);
  std::vector<uint32_t> tris;
  extractBoundary(mesh.tets, adj, tris);

  const float* p = mesh.positions.data();
  const size_t nt = tris.size() / 3;
  std::vector<float> faceNormals(3 * nt);
  out.positions.reserve(9 * nt);
  out.normals.reserve(9 * nt);
  for (size_t t = 0; t < nt; ++t) {
    const float* a = p + 3 * size_t(tris[3 * t]);
    const float* b = p + 3 * size_t(tris[3 * t + 1]);
    const float* c = p + 3 * size_t(tris[3 * t + 2]);
    float u[3], v[3];
    for (int k = 0; k < 3; ++k) { u[k] = b[k] - a[k]; v[k] = c[k] - a[k]; }
    float n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    float len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int k = 0; k < 3; ++k) n[k] = len > 0 ? n[k] / len : 0.f;
    for (const float* q : {a, b, c}) {
      out.positions.insert(out.positions.end(), q, q + 3);
      out.normals.insert(out.normals.end(), n, n + 3);
    }
    std::copy(n, n + 3, &faceNormals[3 * t]);
  }

  // Crease edges: group the triangles' edges by their sorted vertex pair. An edge with two
  // triangles is drawn when their normals differ by more than ~30 degrees (box corners, sharp
  // features); an edge with any other count is an open or non-manifold rim and always drawn.
  struct EdgeUse {
    uint64_t key;
    uint32_t tri;
  };
  std::vector<EdgeUse> edges;
  edges.reserve(3 * nt);
  for (size_t t = 0; t < nt; ++t)
    for (int k = 0; k < 3; ++k) {
      uint32_t a = tris[3 * t + k], b = tris[3 * t + (k + 1) % 3];
      edges.push_back({uint64_t(std::min(a, b)) << 32 | std::max(a, b), uint32_t(t)});
    }
  std::sort(edges.begin(), edges.end(), [](const EdgeUse& x, const EdgeUse& y) { return x.key < y.key; });
  const float kCreaseCos = 0.866f;
  for (size_t i = 0; i < edges.size();) {
    size_t j = i;
    while (j < edges.size() && edges[j].key == edges[i].key) ++j;
    bool draw = j - i != 2;
    if (!draw) {
      const float* n0 = &faceNormals[3 * size_t(edges[i].tri)];
      const float* n1 = &faceNormals[3 * size_t(edges[i + 1].tri)];
      draw = n0[0] * n1[0] + n0[1] * n1[1] + n0[2] * n1[2] < kCreaseCos;
    }
    if (draw) {
      uint32_t a = uint32_t(edges[i].key >> 32), b = uint32_t(edges[i].key);
      out.featureLines.insert(out.featureLines.end(), p + 3 * size_t(a), p + 3 * size_t(a) + 3);
      out.featureLines.insert(out.featureLines.end(), p + 3 * size_t(b), p + 3 * size_t(b) + 3);
    }
    i = j;
  }
}

std::string statsJson(const ViewerState& s) {
  using json = nlohmann::json;
  const Dataset& ds = s.dataset;
  json fields = json::array();
  for (const FieldInfo& f : ds.manifest.fields) fields.push_back(json{{"name", f.name}, {"min", f.range.min}, {"max", f.range.max}});
  json j = {
      {"state", loadStateName(s.state)},
      {"error", s.error},
      {"name", ds.manifest.name},
      {"vertices", ds.pm.mesh.vertexCount()},
      {"tets", ds.pm.mesh.tetCount()},
      {"triangles", s.surface.triangleCount()},
      {"surfaceVertices", s.surface.vertexCount()},
      {"isovalue", s.isovalue},
      {"surfaceArea", s.surfaceArea},
      {"field", s.field >= 0 ? json(ds.manifest.fields[size_t(s.field)].name) : json(nullptr)},
      {"fields", std::move(fields)},
      {"bytesLoaded", s.bytesLoaded},
      {"bytesTotal", ds.manifest.totalBytes()},
      {"chunksLoaded", s.chunksLoaded},
      {"chunksTotal", s.chunksTotal},
      {"firstSurfaceMs", s.firstSurfaceMs >= 0 ? json(s.firstSurfaceMs) : json(nullptr)},
      {"extractMs", s.extractMs},
      {"frameMs", s.frameMs},
      {"showBoundary", s.showBoundary},
      {"sliderRect", {{"x", s.sliderRect.x}, {"y", s.sliderRect.y}, {"w", s.sliderRect.w}, {"h", s.sliderRect.h}}},
  };
  // Messages may carry bytes from the network: never let invalid UTF-8 abort the dump.
  return j.dump(-1, ' ', false, json::error_handler_t::replace);
}

}  // namespace tetstream::viewer
