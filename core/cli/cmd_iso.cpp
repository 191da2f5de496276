// tetstream iso INPUT|PACKDIR --value V [--field NAME] [-o SURFACE.ply] [--json] [--selective [--no-check]]
#include <cmath>
#include <cstdio>
#include <memory>

#include "cli_common.h"
#include "commands.h"
#include "io/ply_writer.h"
#include "isosurface.h"
#include "selective_iso.h"

namespace tetstream::cli {

Runner addIso(CLI::App& app) {
  struct Opts {
    std::string input, field, out;
    double value = 0;
    bool json = false, selective = false, noCheck = false;
    LevelOption level;
    ReadOptions read;
  };
  auto o = std::make_shared<Opts>();
  CLI::App* sub = app.add_subcommand("iso", "Extract an isosurface (marching tetrahedra)");
  sub->add_option("input", o->input, "mesh file or packed dataset folder")->required();
  sub->add_option("--value", o->value, "isovalue")->required();
  sub->add_option("--field", o->field, "scalar field (default: the dataset's first or iso field)");
  sub->add_option("-o,--output", o->out, "write the surface as binary PLY with normals");
  sub->add_flag("--json", o->json, "print the result as JSON on stdout");
  sub->add_flag("--selective", o->selective,
                "packed datasets: load only the nodes this isovalue needs, check the surface against the "
                "full mesh's and report what was needed");
  sub->add_flag("--no-check", o->noCheck, "with --selective: do not load the full mesh to compare");
  addLevelOptions(sub, o->level);
  addReadOptions(sub, o->read);
  return [o] {
    if (o->selective) return runSelectiveIso({o->input, o->field, o->out, o->value, o->json, !o->noCheck});
    Input in;
    if (Result r = loadInput(o->input, in, o->level, o->read); !r) return reportError(r, o->json);
    Result r;
    int f = chooseField(in, o->field, r);
    if (f < 0) return reportError(r, o->json);
    if (!std::isfinite(o->value))
      return reportError(fail(Status::BadArgument, "--value must be a finite number"), o->json);
    IsoExtractor scratch;
    IsoSurface surface;
    Stopwatch sw;
    extractIsosurface(in.mesh, in.mesh.fields[size_t(f)].values, float(o->value), scratch, surface);
    double ms = sw.ms();
    double area = surfaceArea(surface);
    if (!o->out.empty())
      if (Result w = writePly(o->out, surface.positions, surface.normals, surface.indices); !w)
        return reportError(w, o->json);
    if (o->json) {
      printJson({{"field", in.mesh.fields[size_t(f)].name},
                 {"isovalue", float(o->value)},
                 {"tets", in.mesh.tetCount()},
                 {"triangles", surface.triangleCount()},
                 {"vertices", surface.vertexCount()},
                 {"area", area},
                 {"ms", ms}});
    } else {
      std::printf("isosurface %s = %g on %u tets: %u triangles, %u vertices, area %.6g (%.1f ms)\n",
                  in.mesh.fields[size_t(f)].name.c_str(), o->value, in.mesh.tetCount(), surface.triangleCount(),
                  surface.vertexCount(), area, ms);
      if (!o->out.empty()) std::printf("wrote %s\n", o->out.c_str());
    }
    return 0;
  };
}

}  // namespace tetstream::cli
