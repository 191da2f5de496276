// tetstream info INPUT|PACKDIR [--json]
#include <cstdio>
#include <memory>

#include "cli_common.h"
#include "commands.h"
#include "validate.h"

namespace tetstream::cli {

Runner addInfo(CLI::App& app) {
  struct Opts {
    std::string input;
    bool json = false;
    LevelOption level;
    ReadOptions read;
  };
  auto o = std::make_shared<Opts>();
  CLI::App* sub = app.add_subcommand("info", "Counts, fields and ranges, and validation findings");
  sub->add_option("input", o->input, "mesh file or packed dataset folder")->required();
  sub->add_flag("--json", o->json, "print the result as JSON on stdout");
  addLevelOptions(sub, o->level);
  addReadOptions(sub, o->read);
  return [o] {
    Input in;
    Stopwatch sw;
    if (Result r = loadInput(o->input, in, o->level, o->read); !r) return reportError(r, o->json);
    const double readMs = sw.ms();
    const TetMesh& m = in.mesh;
    Bounds b = computeBounds(m.positions);
    ValidationReport v = validateMesh(m);
    if (o->json) {
      json fields = json::array();
      for (const ScalarField& f : m.fields) {
        Range r = computeRange(f.values);
        fields.push_back({{"name", f.name}, {"min", r.min}, {"max", r.max}});
      }
      json j = {{"input", o->input},
                {"packed", in.packed},
                {"name", m.name},
                {"vertices", m.vertexCount()},
                {"tets", m.tetCount()},
                {"bounds", {{"min", b.min}, {"max", b.max}}},
                {"fields", fields},
                {"validation",
                 {{"ok", v.findings.empty()},
                  {"fatal", v.fatal()},
                  {"invertedTets", v.invertedTets},
                  {"zeroVolumeTets", v.zeroVolumeTets},
                  {"duplicateTets", v.duplicateTets},
                  {"unusedVertices", v.unusedVertices},
                  {"nonFinitePositions", v.nonFinitePositions},
                  {"nonFiniteFieldValues", v.nonFiniteFieldValues},
                  {"outOfRangeIndices", v.outOfRangeIndices},
                  {"repeatedVertexTets", v.repeatedVertexTets},
                  {"nonManifoldFaces", v.nonManifoldFaces},
                  {"boundaryFaces", v.boundaryFaces},
                  {"nonManifoldBoundaryEdges", v.nonManifoldBoundaryEdges},
                  {"findings", v.findings}}},
                {"notes", in.notes}};
      if (!in.packed) {
        j["inputFormat"] = in.format;
        j["readMs"] = readMs;
        if (!in.steps.empty()) {
          json steps = json::array();
          for (const TimeStep& s : in.steps) steps.push_back({{"index", s.index}, {"time", s.time}});
          j["steps"] = steps;
          j["stepRead"] = in.stepRead;
        }
      }
      if (in.packed) {
        j["format"] = {{"formatVersion", in.manifest.formatVersion}, {"generator", in.manifest.generator},
                       {"chunks", in.manifest.chunks.size()},        {"nodes", in.manifest.nodes.size()},
                       {"chunksApplied", in.chunksApplied},          {"splitsApplied", in.splitsApplied},
                       {"fullVertices", in.manifest.vertices},       {"fullTets", in.manifest.tets},
                       {"bytes", in.manifest.totalBytes()},          {"isoField", in.manifest.isoField}};
      }
      printJson(j);
      return 0;
    }
    std::printf("%s%s\n", o->input.c_str(), in.packed ? " (packed dataset)" : "");
    std::printf("  name      %s\n", m.name.c_str());
    if (!in.packed) std::printf("  read      %s in %.0f ms\n", in.format.c_str(), readMs);
    if (!in.steps.empty()) {
      std::printf("  steps     %zu, read step %llu (t = %g)\n", in.steps.size(),
                  static_cast<unsigned long long>(in.stepRead), in.steps[in.stepRead].time);
      // A long run lists its first and last steps (--json has them all).
      const size_t n = in.steps.size(), shown = 5;
      for (size_t i = 0; i < n; ++i) {
        if (n > 2 * shown + 2 && i == shown) {
          std::printf("  step      ... %zu more\n", n - 2 * shown);
          i = n - shown - 1;
          continue;
        }
        std::printf("  step      %4llu  t = %g\n", static_cast<unsigned long long>(in.steps[i].index),
                    in.steps[i].time);
      }
    }
    std::printf("  vertices  %u\n  tets      %u\n", m.vertexCount(), m.tetCount());
    std::printf("  bounds    [%g, %g, %g] .. [%g, %g, %g]\n", b.min[0], b.min[1], b.min[2], b.max[0], b.max[1],
                b.max[2]);
    for (const ScalarField& f : m.fields) {
      Range r = computeRange(f.values);
      std::printf("  field     %-24s [%g, %g]\n", f.name.c_str(), r.min, r.max);
    }
    if (in.packed) {
      std::printf("  format    v%u, %zu chunk(s), %zu node(s), %llu bytes, by %s\n", in.manifest.formatVersion,
                  in.manifest.chunks.size(), in.manifest.nodes.size(),
                  static_cast<unsigned long long>(in.manifest.totalBytes()), in.manifest.generator.c_str());
      std::printf("  level     %u of %zu chunks, %u splits: %.1f%% of %u vertices, %.1f%% of %u tets\n",
                  in.chunksApplied, in.manifest.chunks.size(), in.splitsApplied,
                  100.0 * m.vertexCount() / in.manifest.vertices, in.manifest.vertices,
                  100.0 * m.tetCount() / in.manifest.tets, in.manifest.tets);
    }
    std::printf("  boundary  %llu faces\n", static_cast<unsigned long long>(v.boundaryFaces));
    for (const std::string& n : in.notes) std::printf("  note      %s\n", n.c_str());
    if (v.findings.empty()) std::printf("  valid     no problems found\n");
    for (const std::string& f : v.findings) std::printf("  problem   %s\n", f.c_str());
    return 0;
  };
}

}  // namespace tetstream::cli
