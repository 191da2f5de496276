// Shared pieces of the tetstream subcommands: loading any input (mesh file or packed folder),
// error reporting (plain text on stderr, JSON on stdout with --json) and timing.
#pragma once
#include <CLI/CLI.hpp>
#include <chrono>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "io/mesh_io.h"
#include "manifest.h"
#include "mesh.h"
#include "status.h"

namespace tetstream::cli {

using json = nlohmann::ordered_json;

// Which level of a packed dataset to use: the first `chunks` chunks (1 = the base mesh), or
// the first level with at least `fraction` of the full vertex count. Default: everything.
struct LevelOption {
  int chunks = -1;
  double fraction = -1;
};
void addLevelOptions(CLI::App* sub, LevelOption& level);

struct Input {
  TetMesh mesh;
  bool packed = false;
  Manifest manifest;               // when packed
  uint32_t chunksApplied = 0;      // when packed: complete chunks
  uint32_t splitsApplied = 0;      // when packed: vertex splits applied
  std::vector<std::string> notes;  // what the reader did (converted fields, skipped cells)
  std::string format;              // mesh files: what the reader read (ReadReport::format)
  std::vector<TimeStep> steps;     // mesh files with time steps: all of them
  uint64_t stepRead = 0;           // ... and the one read
};

// --q FILE: the solution file of a PLOT3D grid (Q) or of a Medit mesh (.sol); --step K or
// --time T: the time step of a file with several.
void addReadOptions(CLI::App* sub, ReadOptions& read);

// A packed dataset folder (with manifest.json) or a mesh file (any format readMesh reads).
Result loadInput(const std::string& path, Input& in, const LevelOption& level = {}, const ReadOptions& read = {});

// Picks the field by name, or the dataset's default (isoField for packed data, else the first).
// Returns its index or sets `r` to a MissingField error listing the available names.
int chooseField(const Input& in, const std::string& name, Result& r);

// Prints `r` and returns the process exit code (1).
int reportError(const Result& r, bool asJson);

void printJson(const json& j);

class Stopwatch {
 public:
  double ms() const {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0_).count();
  }

 private:
  std::chrono::steady_clock::time_point t0_ = std::chrono::steady_clock::now();
};

}  // namespace tetstream::cli
