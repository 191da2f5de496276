#include "cli_common.h"

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "dataset.h"
#include "io/mesh_io.h"

namespace tetstream::cli {

void addLevelOptions(CLI::App* sub, LevelOption& level) {
  auto* c = sub->add_option("--chunks", level.chunks, "packed input: use the first K chunks (1 = the base mesh)")
                ->check(CLI::Range(1, 1 << 20));
  auto* f = sub->add_option("--fraction", level.fraction, "packed input: refine until this fraction of the vertices")
                ->check(CLI::Range(0.0, 1.0));
  c->excludes(f);
}

void addReadOptions(CLI::App* sub, ReadOptions& read) {
  sub->add_option("--q,--solution", read.solution,
                  "PLOT3D Q file for a grid (default: a sibling such as bluntfinq.bin for bluntfinxyz.bin), or a "
                  "Medit .sol (default: NAME.sol)");
  auto* step = sub->add_option("--step", read.step, "files with time steps: read step K (0-based; default: the last)");
  auto* time = sub->add_option("--time", read.time, "files with time steps: read the step nearest simulation time T");
  step->excludes(time);
}

Result loadInput(const std::string& path, Input& in, const LevelOption& level, const ReadOptions& read) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    if (!isPackedDir(path))
      return fail(Status::IoError, path + ": a folder without manifest.json is not a packed dataset");
    if (!read.solution.empty()) return fail(Status::BadArgument, "--q applies to mesh files, not to packed datasets");
    if (read.step || read.time)
      return fail(Status::BadArgument, "--step and --time apply to mesh files, not to packed datasets");
    Dataset ds;
    uint32_t maxVertices = ~0u;
    if (level.fraction >= 0) {
      // The manifest is read twice (once here for the count): it is small.
      Dataset probe;
      if (Result r = loadPackedDir(path, probe, 0); !r) return r;
      maxVertices = uint32_t(std::ceil(level.fraction * probe.manifest.vertices));
    }
    if (Result r = loadPackedDir(path, ds, level.chunks, maxVertices); !r) return r;
    in.packed = true;
    in.manifest = ds.manifest;
    in.chunksApplied = ds.chunksApplied();
    in.splitsApplied = ds.pm.splitsApplied();
    in.mesh = std::move(ds.pm.mesh);
    return Result::success();
  }
  if (level.chunks >= 0 || level.fraction >= 0)
    return fail(Status::BadArgument, "--chunks and --fraction apply to packed datasets, not to " + path);
  ReadReport report;
  Result r = readMesh(path, in.mesh, report, read);
  in.format = report.format;
  in.notes = report.notes;
  in.steps = report.steps;
  in.stepRead = report.stepRead;
  if (r && in.mesh.name.empty()) in.mesh.name = std::filesystem::path(path).stem().string();
  return r;
}

int chooseField(const Input& in, const std::string& name, Result& r) {
  std::string want = name;
  if (want.empty()) {
    if (in.mesh.fields.empty()) {
      r = fail(Status::MissingField, "the mesh has no point scalar field");
      return -1;
    }
    want = in.packed && !in.manifest.isoField.empty() ? in.manifest.isoField : in.mesh.fields[0].name;
  }
  int f = in.mesh.findField(want);
  if (f < 0) {
    std::string names;
    for (const ScalarField& s : in.mesh.fields) names += (names.empty() ? "" : ", ") + s.name;
    r = fail(Status::MissingField, "no field named '" + want + "' (fields: " + (names.empty() ? "none" : names) + ")");
  }
  return f;
}

int reportError(const Result& r, bool asJson) {
  std::fprintf(stderr, "tetstream: error: %s\n", r.message.c_str());
  if (asJson) printJson({{"error", {{"status", statusName(r.status)}, {"message", r.message}}}});
  return 1;
}

void printJson(const json& j) { std::printf("%s\n", j.dump(2).c_str()); }

}  // namespace tetstream::cli
