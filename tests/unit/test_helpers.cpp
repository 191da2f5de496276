#include "test_helpers.h"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>

#include <zstd.h>

#include "chunk.h"
#include "pack/chunk_encode.h"
#include "io/generators.h"
#include "split_stream.h"

namespace tetstream::test {

// ------------------------------------------------------------------ readers (test_readers.cpp)

std::string fixturePath(const std::string& name) { return std::string(TETSTREAM_FIXTURES) + "/" + name; }

std::vector<std::string> fixtureFiles() {
  std::vector<std::string> out;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(TETSTREAM_FIXTURES, ec)) {
    std::string ext = e.path().extension().string();
    if (ext == ".vtu" || ext == ".vtk") out.push_back(e.path().filename().string());
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::string loadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

bool saveFile(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), std::streamsize(bytes.size()));
  return bool(out);
}

ScratchDir::ScratchDir(const std::string& name) {
  auto dir = std::filesystem::temp_directory_path() / ("tetstream-" + name + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  path = dir.string();
}

ScratchDir::~ScratchDir() {
  std::error_code ec;
  std::filesystem::remove_all(path, ec);
}

TetMesh harmonicMesh(uint32_t n) {
  TetMesh m = makeGridMesh(n);
  addHarmonicField(m);
  addDistanceField(m);
  m.name = "harmonic";
  return m;
}

std::string suiteDir(const std::string& suite, const std::string& name) {
  static std::map<std::string, std::unique_ptr<ScratchDir>> roots;  // destroyed at exit
  auto& root = roots[suite];
  if (!root) root = std::make_unique<ScratchDir>(suite);
  std::string dir = root->path + "/" + name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

std::vector<uint8_t> forgeTruncatedChunk(const std::vector<uint8_t>& file, ChunkInfo& info) {
  std::vector<uint8_t> raw(info.rawBytes);
  if (ZSTD_decompress(raw.data(), raw.size(), file.data(), file.size()) != raw.size()) return {};
  raw.pop_back();  // the last record ends early
  // In columns, the last column (Values) one byte shorter too, so the chunk passes its header.
  uint32_t flags, last;
  std::memcpy(&flags, &raw[kChunkHeaderBytes + 4], 4);
  if (flags & kSplitFlagColumns) {
    const size_t at = kChunkHeaderBytes + 8 + 4 * (kSplitColumns - 1);
    std::memcpy(&last, &raw[at], 4);
    if (last == 0) return {};
    --last;
    std::memcpy(&raw[at], &last, 4);
  }
  std::vector<uint8_t> bad;
  ChunkInfo forged = info;
  if (!finishChunk(raw, 3, bad, forged)) return {};
  info.bytes = forged.bytes;
  info.rawBytes = forged.rawBytes;
  info.hash = forged.hash;
  return bad;
}

int runCommand(const std::string& command, std::string& output) {
  output.clear();
  std::FILE* p = ::popen(command.c_str(), "r");
  if (!p) return -1;
  char buf[4096];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) output.append(buf, n);
  int status = ::pclose(p);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

bool haveMeshioPython() {
  static const bool have = [] {
    std::string out;
    return runCommand("/usr/bin/python3 -c 'import meshio' 2>/dev/null", out) == 0;
  }();
  return have;
}

}  // namespace tetstream::test
