#include "huge_pages.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
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
// written once each (well under a microsecond on bare hardware, tens of microseconds on some
// virtual machines, where the probe still takes only milliseconds).
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

// The heap settings added for a small input (see useHugePages): the heap grows 32 MB at a time
// and blocks up to 32 MB come from it, unless the user set these tunables already.
std::string smallInputTunables(const char* userTunables) {
  std::string extra;
  for (const char* setting : {"glibc.malloc.top_pad=33554432", "glibc.malloc.mmap_threshold=33554432"}) {
    const std::string name(setting, std::strchr(setting, '=') + 1);
    if (!userTunables || !std::strstr(userTunables, name.c_str())) extra += std::string(":") + setting;
  }
  return extra;
}
#endif

}  // namespace

// Why: packing touches about 2.5 times its peak memory afresh (arrays freed and allocated again
// phase after phase: the file, the face pairing, the simplifier's and the encoder's arrays), and
// on some virtual machines a first touch is expensive, so that page faults become a large share
// of a pack's time. glibc asks the kernel for huge pages (2 MB, one fault instead of 512) when
// the tunable glibc.malloc.hugetlb=1 is set at start, and a running program cannot set it for
// itself: so the program starts itself again, once, with it set. The output is the same; peak
// memory grows by a few percent. The second start costs what the dynamic loader takes (a few
// ms to about 20 with the HPC container libraries), nothing next to a pack it speeds up. A file's size does not tell a
// small mesh from a large one (a structured grid's file is tiny), so every command that reads an input does it (all but
// gen). Not done when the kernel gives huge pages to every program anyway ("always") or to none
// ("never"), when the tunable is set already, under valgrind (its tools would lose the program)
// or with TETSTREAM_HUGE_PAGES=0. Nor where a first touch is cheap (kCheapPageMicroseconds):
// there fewer faults can gain little, and huge pages can cost (slower reading).
//
// A small input (a file under 4 MB) also gets a heap that grows 32 MB at a time, every block up
// to 32 MB taken from it (glibc's top_pad and mmap_threshold). glibc advises huge pages on each
// growth of the heap only when that growth is 2 MB or more; grown a little at a time, a small
// pack's heap stays in 4 KB pages, and blocks of 128 KB to 2 MB are mapped and unmapped afresh,
// so these settings remove most of a small pack's page faults for a MB or two of peak memory.
// Not for larger files: there they gain nothing measurable and cost more peak memory, as they
// also stop glibc from moving its own threshold up. Structured files that fool the size test
// come out the same either way.
// Figures: docs/design-notes.md.
void useHugePages(char** argv, const std::string& input) {
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
  constexpr std::uintmax_t kSmallInputBytes = 4u << 20;
  std::error_code error;
  const std::uintmax_t bytes =
      std::filesystem::is_regular_file(input, error) ? std::filesystem::file_size(input, error) : 0;
  const bool small = !error && bytes > 0 && bytes < kSmallInputBytes;
  const std::string value = (tunables && *tunables ? std::string(tunables) + ":" : std::string()) +
                            "glibc.malloc.hugetlb=1" + (small ? smallInputTunables(tunables) : std::string());
  if (setenv("GLIBC_TUNABLES", value.c_str(), 1) != 0 || setenv("TETSTREAM_RESTARTED", "1", 1) != 0) return;
  std::fflush(nullptr);
  execv("/proc/self/exe", argv);  // returns only if it failed: go on with small pages
#else
  (void)argv;
  (void)input;
#endif
}

}  // namespace tetstream::cli
