#include "huge_pages.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#if defined(__linux__) && defined(__GLIBC__)
#include <sys/mman.h>
#include <unistd.h>

#include <chrono>
#endif

namespace tetstream::cli {
namespace {

#if defined(__linux__) && defined(__GLIBC__)
// What a first touch of a fresh 4 KB page costs here, in microseconds: 64 pages of a new mapping
// written once each (about 0.3–1 µs on a machine of its own, 8–30 µs on this project's virtual
// machines; the probe takes 2 ms there).
double microsecondsPerFreshPage() {
  constexpr size_t kPages = 64, kPage = 4096;
  const auto start = std::chrono::steady_clock::now();
  void* map = mmap(nullptr, kPages * kPage, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (map == MAP_FAILED) return 0;
  volatile char* bytes = static_cast<char*>(map);
  for (size_t k = 0; k < kPages; ++k) bytes[k * kPage] = 1;
  munmap(map, kPages * kPage);
  return std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count() / kPages;
}
#endif

}  // namespace

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
// 1.8M tets), so every command that reads an input does it (all but gen). Not done when the kernel gives huge
// pages to every program anyway ("always") or to none ("never"), when the tunable is set already,
// under valgrind (its tools would lose the program) or with TETSTREAM_HUGE_PAGES=0. Nor where a
// first touch is cheap (under 2 µs a page), as there fewer faults can gain little, and huge pages
// have been seen to cost: on session 16's machine the simplifier was no faster with them and
// reading 2.3× slower.
void useHugePages(char** argv) {
#if defined(__linux__) && defined(__GLIBC__)
  constexpr double kCheapPageMicroseconds = 2.0;
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
  if (microsecondsPerFreshPage() < kCheapPageMicroseconds) return;
  const std::string value =
      tunables && *tunables ? std::string(tunables) + ":glibc.malloc.hugetlb=1" : "glibc.malloc.hugetlb=1";
  if (setenv("GLIBC_TUNABLES", value.c_str(), 1) != 0 || setenv("TETSTREAM_RESTARTED", "1", 1) != 0) return;
  std::fflush(nullptr);
  execv("/proc/self/exe", argv);  // returns only if it failed: go on with small pages
#else
  (void)argv;
#endif
}

}  // namespace tetstream::cli
