#include "huge_pages.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#if defined(__linux__) && defined(__GLIBC__)
#include <unistd.h>
#endif

namespace tetstream::cli {
namespace {

char** commandLine = nullptr;

}  // namespace

void rememberCommandLine(char** argv) { commandLine = argv; }

// Why: packing touches about 2.5 times its peak memory afresh (arrays freed and allocated again
// phase after phase: the file, the face pairing, the simplifier's and the encoder's arrays), and
// on virtual machines such as this project's a first touch is expensive: 128,000 page faults cost
// Harmonic 64³'s pack 1.2 s of system time. glibc asks the kernel for huge pages (2 MB, one fault
// instead of 512) when the tunable glibc.malloc.hugetlb=1 is set at start, and a running program
// cannot set it for itself: so the program starts itself again, once, with it set. Measured
// (medians, the two settings taking turns): Harmonic 64³ to 5% 6.8 -> 5.5 s (reading 0.82 ->
// 0.40 s, checks 0.37 -> 0.17 s), carotid 4.5 -> 3.7 s, Harmonic 24³ 491 -> 432 ms, peak memory
// +3%; the output is the same. The second start costs ~6 ms here (post.vtk, 8,750 tets, gains about
// as much); a file's size does not tell a small mesh from a large one (ironProt.vtk's 314 KB hold
// 1.8M tets), so every command that reads an input does it. Not done when the kernel gives huge
// pages to every program anyway ("always") or to none ("never"), when the tunable is set already,
// under valgrind (its tools would lose the program) or with TETSTREAM_HUGE_PAGES=0.
void useHugePages() {
#if defined(__linux__) && defined(__GLIBC__)
  if (!commandLine) return;
  const char* optOut = std::getenv("TETSTREAM_HUGE_PAGES");
  if (optOut && std::strcmp(optOut, "0") == 0) return;
  if (std::getenv("TETSTREAM_RESTARTED")) return;  // (never twice, whatever glibc does with the tunable)
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  if (tunables && std::strstr(tunables, "glibc.malloc.hugetlb")) return;
  const char* preload = std::getenv("LD_PRELOAD");
  if (preload && std::strstr(preload, "vgpreload")) return;
  std::ifstream mode("/sys/kernel/mm/transparent_hugepage/enabled");
  const std::string modes((std::istreambuf_iterator<char>(mode)), std::istreambuf_iterator<char>());
  if (modes.find("[madvise]") == std::string::npos) return;
  const std::string value =
      tunables && *tunables ? std::string(tunables) + ":glibc.malloc.hugetlb=1" : "glibc.malloc.hugetlb=1";
  if (setenv("GLIBC_TUNABLES", value.c_str(), 1) != 0 || setenv("TETSTREAM_RESTARTED", "1", 1) != 0) return;
  std::fflush(nullptr);
  execv("/proc/self/exe", commandLine);  // returns only if it failed: go on with small pages
#endif
}

}  // namespace tetstream::cli
