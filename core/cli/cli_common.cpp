#include "cli_common.h"

#include <cstdio>
#include <filesystem>

#include "dataset.h"
#include "pack/mesh_io.h"

namespace tetstream::cli {

Result loadInput(const std::string& path, Input& in) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    if (!isPackedDir(path)) return fail(Status::IoError, path + ": a folder without manifest.json is not a packed dataset");
    Dataset ds;
    if (Result r = loadPackedDir(path, ds); !r) return r;
    in.packed = true;
    in.manifest = ds.manifest;
    in.chunksApplied = ds.chunksApplied;
    in.mesh = std::move(ds.mesh);
    return Result::success();
  }
  ReadReport report;
  Result r = readMesh(path, in.mesh, report);
  in.notes = report.notes;
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
