// tetstream: pack tetrahedral simulation meshes for progressive streaming, and inspect them.
#include <cstdio>
#include <map>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "commands.h"
#include "dist/comm.h"
#include "huge_pages.h"
#include "manifest.h"

int main(int argc, char** argv) {
#if defined(__GLIBC__)
  // One malloc arena for all threads: the packer's two simplifier threads grow and free star
  // lists that other threads allocated, and separate arenas keep tens of MB more at the peak.
  mallopt(M_ARENA_MAX, 1);
#endif
  using namespace tetstream::cli;
  CLI::App app{"tetstream: progressive isosurface streaming of tetrahedral meshes"};
  app.set_version_flag("--version", std::string("tetstream ") + tetstream::kLibraryVersion);
  app.require_subcommand(1);
  std::map<CLI::App*, Runner> runners;
  for (auto add : {addGen, addPack, addUnpack, addIso, addInfo}) {
    size_t before = app.get_subcommands({}).size();
    Runner run = add(app);
    runners[app.get_subcommands({})[before]] = run;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  for (auto& [sub, run] : runners) {
    if (!sub->parsed()) continue;
    // Every command but gen reads a mesh or a packed dataset: decided once, before any work
    // (the program may start again here, with huge pages: huge_pages.h).
    // (Not under an MPI launcher: the restart would leave the launcher's process behind.)
    if (sub->get_name() != "gen" && !tetstream::dist::launchedByMpi()) {
      const CLI::Option* input = sub->get_option_no_throw("input");
      useHugePages(argv, input && input->count() ? input->as<std::string>() : std::string());
    }
    return run();
  }
  return 2;
}
