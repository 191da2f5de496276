// tetstream unpack PACKDIR [--fraction F | --chunks K] -o MESH.vtu [--json]
#include <cstdio>
#include <memory>

#include "cli_common.h"
#include "commands.h"
#include "io/mesh_io.h"

namespace tetstream::cli {

Runner addUnpack(CLI::App& app) {
  struct Opts {
    std::string input, out;
    bool json = false;
    LevelOption level;
  };
  auto o = std::make_shared<Opts>();
  CLI::App* sub = app.add_subcommand("unpack", "Write the mesh of one level of a packed dataset (all fields) as .vtu");
  sub->add_option("input", o->input, "packed dataset folder")->required();
  sub->add_option("-o,--output", o->out, "output .vtu file")->required();
  sub->add_flag("--json", o->json, "print the result as JSON on stdout");
  addLevelOptions(sub, o->level);
  return [o] {
    Stopwatch sw;
    Input in;
    if (Result r = loadInput(o->input, in, o->level); !r) return reportError(r, o->json);
    if (!in.packed)
      return reportError(fail(Status::BadArgument, o->input + " is not a packed dataset folder"), o->json);
    if (Result r = writeMesh(o->out, in.mesh); !r) return reportError(r, o->json);
    const TetMesh& m = in.mesh;
    if (o->json) {
      printJson({{"output", o->out},
                 {"vertices", m.vertexCount()},
                 {"tets", m.tetCount()},
                 {"chunksApplied", in.chunksApplied},
                 {"splitsApplied", in.splitsApplied},
                 {"fraction", double(m.vertexCount()) / in.manifest.vertices},
                 {"ms", sw.ms()}});
    } else {
      std::printf("wrote %s: %u vertices (%.1f%%), %u tets, %zu field(s), %u chunk(s) + %u splits applied\n",
                  o->out.c_str(), m.vertexCount(), 100.0 * m.vertexCount() / in.manifest.vertices, m.tetCount(),
                  m.fields.size(), in.chunksApplied, in.splitsApplied);
    }
    return 0;
  };
}

}  // namespace tetstream::cli
