// tetstream pack INPUT -o OUTDIR [--field NAME]
#include <cstdio>
#include <memory>

#include "cli_common.h"
#include "commands.h"
#include "pack/packer.h"

namespace tetstream::cli {

Runner addPack(CLI::App& app) {
  struct Opts { std::string input, out, field, name; int level = 9; bool json = false; };
  auto o = std::make_shared<Opts>();
  CLI::App* sub = app.add_subcommand("pack", "Pack a mesh into a streamable dataset folder (manifest + chunks)");
  sub->add_option("input", o->input, "mesh file (.vtu, .vtk)")->required();
  sub->add_option("-o,--output", o->out, "output folder (created; an earlier pack there is replaced)")->required();
  sub->add_option("--field", o->field, "field shown first and used to steer simplification (default: the first)");
  sub->add_option("--name", o->name, "dataset name shown in the viewer (default: the file name)");
  sub->add_option("--zstd-level", o->level, "zstd compression level")->check(CLI::Range(1, 22))->capture_default_str();
  sub->add_flag("--json", o->json, "print the result as JSON on stdout");
  return [o] {
    Stopwatch total;
    Input in;
    if (Result r = loadInput(o->input, in); !r) return reportError(r, o->json);
    if (in.packed) return reportError(fail(Status::BadArgument, o->input + " is already packed; give a mesh file"), o->json);
    double readMs = total.ms();
    PackOptions opt{o->field, o->name, o->level};
    PackSummary s;
    Stopwatch packTime;
    if (Result r = packMesh(std::move(in.mesh), o->out, opt, s); !r) return reportError(r, o->json);
    const Manifest& m = s.manifest;
    uint64_t bytes = m.totalBytes();
    double bitsPerTet = 8.0 * double(bytes) / m.tets;
    if (o->json) {
      json notes = in.notes;
      for (const std::string& n : s.notes) notes.push_back(n);
      printJson({{"output", o->out}, {"name", m.name}, {"vertices", m.vertices}, {"tets", m.tets},
                 {"field", m.isoField}, {"chunks", m.chunks.size()}, {"bytes", bytes}, {"bitsPerTet", bitsPerTet},
                 {"readMs", readMs}, {"packMs", packTime.ms()}, {"ms", total.ms()}, {"notes", notes}});
      return 0;
    }
    for (const std::string& n : in.notes) std::printf("note: %s\n", n.c_str());
    for (const std::string& n : s.notes) std::printf("note: %s\n", n.c_str());
    std::printf("packed %s -> %s/\n", o->input.c_str(), o->out.c_str());
    std::printf("  %u vertices, %u tets, field '%s', %zu chunk(s), %.2f MB (%.1f bits/tet)\n", m.vertices, m.tets,
                m.isoField.c_str(), m.chunks.size(), bytes / 1e6, bitsPerTet);
    std::printf("  read %.0f ms, pack %.0f ms\n", readMs, packTime.ms());
    return 0;
  };
}

}  // namespace tetstream::cli
