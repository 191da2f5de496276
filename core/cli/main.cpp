// tetstream: pack tetrahedral simulation meshes for progressive streaming, and inspect them.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#if defined(__GLIBC__)
#include <malloc.h>
#endif
#if defined(__linux__) && defined(__GLIBC__)
#include <unistd.h>
#endif

#include "commands.h"
#include "manifest.h"

namespace {

#if defined(__linux__) && defined(__GLIBC__)
// Transparent huge pages for the heap. Packing touches about 2.5 times its peak memory afresh
// (arrays freed and allocated again phase after phase: the file, the face pairing, the
// simplifier's and the encoder's arrays), and on virtual machines such as this project's a first
// touch is expensive: 128,000 page faults cost Harmonic 64³'s pack 1.2 s of system time. glibc
// asks for huge pages (2 MB, one fault instead of 512) when the tunable glibc.malloc.hugetlb=1 is
// set at start, and a program cannot set it for itself once running: so the program starts
// itself again, once, with it set. Measured: Harmonic 64³ to 5% 6.7 -> 5.2 s (reading 0.8 ->
// 0.4 s, checks 0.38 -> 0.15 s), carotid 4.1 -> 3.5 s, peak memory +3%; the output is the same.
// Not done when the kernel gives huge pages to every program anyway ("always") or to none
// ("never"), when the tunable is set already, under valgrind (its tools would lose the program)
// or with TETSTREAM_HUGE_PAGES=0.
void restartWithHugePages(char** argv) {
  const char* optOut = std::getenv("TETSTREAM_HUGE_PAGES");
  if (optOut && std::strcmp(optOut, "0") == 0) return;
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  if (tunables && std::strstr(tunables, "glibc.malloc.hugetlb")) return;
  const char* preload = std::getenv("LD_PRELOAD");
  if (preload && std::strstr(preload, "vgpreload")) return;
  std::ifstream mode("/sys/kernel/mm/transparent_hugepage/enabled");
  const std::string modes((std::istreambuf_iterator<char>(mode)), std::istreambuf_iterator<char>());
  if (modes.find("[madvise]") == std::string::npos) return;
  const std::string value = tunables && *tunables ? std::string(tunables) + ":glibc.malloc.hugetlb=1" : "glibc.malloc.hugetlb=1";
  if (setenv("GLIBC_TUNABLES", value.c_str(), 1) != 0) return;
  execv("/proc/self/exe", argv);  // returns only if it failed: go on with small pages
}
#endif

}  // namespace

int main(int argc, char** argv) {
#if defined(__linux__) && defined(__GLIBC__)
  restartWithHugePages(argv);
#endif
#if defined(__GLIBC__)
  // One malloc arena for all threads: the packer's two simplifier threads grow and free star
  // lists that other threads allocated, and separate arenas kept 24 MB more at the peak
  // (Harmonic 64³).
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
  for (auto& [sub, run] : runners)
    if (sub->parsed()) return run();
  return 2;
}
