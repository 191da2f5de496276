// tetstream gen harmonic|distance --n N -o FILE.vtu|FILE.pvtu [--pieces K]
#include <cstdio>
#include <memory>

#include "cli_common.h"
#include "commands.h"
#include "io/generators.h"
#include "io/mesh_io.h"

namespace tetstream::cli {

Runner addGen(CLI::App& app) {
  struct Opts {
    std::string kind, out;
    uint32_t n = 32, pieces = 4;
    bool json = false;
  };
  auto o = std::make_shared<Opts>();
  CLI::App* sub = app.add_subcommand("gen", "Generate a built-in dataset as a .vtu file (or .pvtu pieces)");
  sub->add_option("kind", o->kind, "harmonic (the paper's analytic dataset) or distance (|p|, spheres)")
      ->required()
      ->check(CLI::IsMember({"harmonic", "distance"}));
  sub->add_option("--n", o->n, "vertices per axis of the grid; (n-1)^3*6 tets, n=64 gives 1.5M")
      ->check(CLI::Range(2u, 1024u))
      ->capture_default_str();
  sub->add_option("-o,--output", o->out, "output file: .vtu, or .pvtu for the pieces a parallel run writes")
      ->required();
  sub->add_option("--pieces", o->pieces, "pieces of a .pvtu (a folder of .vtu files beside it)")
      ->check(CLI::Range(1u, 65536u))
      ->capture_default_str();
  sub->add_flag("--json", o->json, "print the result as JSON on stdout");
  return [o] {
    Stopwatch sw;
    TetMesh m = makeGridMesh(o->n);
    if (o->kind == "harmonic")
      addHarmonicField(m);
    else
      addDistanceField(m);
    m.name = o->kind;
    if (Result r = writeMesh(o->out, m, o->pieces); !r) return reportError(r, o->json);
    if (o->json) {
      printJson({{"file", o->out},
                 {"vertices", m.vertexCount()},
                 {"tets", m.tetCount()},
                 {"field", m.fields[0].name},
                 {"ms", sw.ms()}});
    } else {
      std::printf("wrote %s: %s, %u vertices, %u tets, field '%s' (%.0f ms)\n", o->out.c_str(), o->kind.c_str(),
                  m.vertexCount(), m.tetCount(), m.fields[0].name.c_str(), sw.ms());
    }
    return 0;
  };
}

}  // namespace tetstream::cli
