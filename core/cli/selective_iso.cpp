#include "selective_iso.h"

#include <cmath>
#include <cstdio>

#include "cli_common.h"
#include "dataset.h"
#include "io/ply_writer.h"
#include "isosurface.h"
#include "partial.h"

namespace tetstream::cli {

int runSelectiveIso(const SelectiveIsoOptions& o) {
  if (!isPackedDir(o.dir))
    return reportError(fail(Status::BadArgument, "--selective needs a packed dataset folder, not " + o.dir), o.json);
  if (!std::isfinite(o.value)) return reportError(fail(Status::BadArgument, "--value must be a finite number"), o.json);
  std::string manifestJson;
  Manifest m;
  if (Result r = readManifestFile(o.dir, manifestJson); !r) return reportError(r, o.json);
  if (Result r = parseManifest(manifestJson, m); !r) return reportError(r, o.json);
  const int f = m.findField(o.field.empty() ? m.isoField : o.field);
  if (f < 0) return reportError(fail(Status::MissingField, "no field named '" + o.field + "'"), o.json);

  // The nodes the isovalue needs; a dataset without a hierarchy needs every chunk.
  std::vector<uint32_t> nodes = nodesForIsovalue(m, f, float(o.value));
  const bool hierarchy = !m.nodes.empty();
  if (!hierarchy)
    for (uint32_t k = 0; k < m.nodes.size(); ++k) nodes.push_back(k);
  Stopwatch sw;
  PartialDataset pd;
  TetMesh full;
  uint64_t bytes = 0;
  uint32_t applied = 0;
  if (hierarchy) {
    if (Result r = loadPartialDir(o.dir, nodes, pd); !r) return reportError(r, o.json);
    bytes = pd.bytesLoaded;
    applied = uint32_t(pd.applied.size());
  }
  const double loadMs = sw.ms();
  // The error of the field that steered the simplification, of the mesh loaded: in the regions
  // the isovalue did not need refined (none of another field is in the manifest).
  std::vector<uint8_t> loaded(m.nodes.size(), 0);
  for (uint32_t k : pd.applied) loaded[k] = 1;
  const double elsewhere = f == m.findField(m.isoField) ? frontierFieldError(m, loaded).measured : -1;
  Input whole;
  if ((o.check || !hierarchy))
    if (Result r = loadInput(o.dir, whole); !r) return reportError(r, o.json);
  if (!hierarchy) bytes = m.totalBytes();
  const TetMesh& mesh = hierarchy ? pd.pm.mesh : whole.mesh;

  IsoExtractor scratch;
  IsoSurface surface, reference;
  extractIsosurface(mesh, mesh.fields[size_t(f)].values, float(o.value), scratch, surface);
  bool exact = !hierarchy;
  if (o.check && hierarchy) {
    extractIsosurface(whole.mesh, whole.mesh.fields[size_t(f)].values, float(o.value), scratch, reference);
    exact = sameTriangles(surface, reference);
  }
  const double area = surfaceArea(surface);
  if (!o.out.empty())
    if (Result w = writePly(o.out, surface.positions, surface.normals, surface.indices); !w)
      return reportError(w, o.json);
  const uint64_t total = m.totalBytes();
  if (o.json) {
    json j = {{"field", m.fields[size_t(f)].name},
              {"isovalue", float(o.value)},
              {"triangles", surface.triangleCount()},
              {"vertices", surface.vertexCount()},
              {"area", area},
              {"bytes", bytes},
              {"bytesTotal", total},
              {"nodes", applied},
              {"nodesTotal", m.nodes.size()},
              {"tets", mesh.tetCount()},
              {"tetsTotal", m.tets},
              {"fieldMax", elsewhere >= 0 ? json(elsewhere) : json(nullptr)},
              {"loadMs", loadMs}};
    if (o.check) j["exact"] = exact;
    if (o.check && hierarchy) j["trianglesFull"] = reference.triangleCount();
    printJson(j);
  } else {
    std::printf("isosurface %s = %g: %u triangles, area %.6g\n", m.fields[size_t(f)].name.c_str(), o.value,
                surface.triangleCount(), area);
    std::printf("  needed    %u of %zu nodes, %.2f of %.2f MB (%.1f%%), %u of %u tets (%.0f ms)\n", applied,
                m.nodes.size(), bytes / 1e6, total / 1e6, 100.0 * double(bytes) / double(total), mesh.tetCount(),
                m.tets, loadMs);
    if (hierarchy && elsewhere >= 0) {
      const Range r = m.fields[size_t(f)].range;
      std::printf("  elsewhere field error up to %.3g (%.2g%% of the range) in the regions left coarse\n", elsewhere,
                  r.max > r.min ? 100 * elsewhere / (double(r.max) - r.min) : 0.0);
    }
    if (!hierarchy) std::printf("  note      this dataset has no patch hierarchy: every chunk is needed\n");
    if (o.check)
      std::printf("  check     %s\n",
                  exact ? "the same triangles as the full mesh's surface" : "DIFFERS from the full mesh's surface");
    if (!o.out.empty()) std::printf("wrote %s\n", o.out.c_str());
  }
  return o.check && !exact ? 1 : 0;
}

}  // namespace tetstream::cli
