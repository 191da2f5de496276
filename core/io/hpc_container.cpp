// What lies under an Exodus II or CGNS file, found before any reader is chosen: the container's
// signature (netCDF classic, HDF5, ADF) and, for a file whose extension names no format, whether
// its content is Exodus II or CGNS (asked of netCDF and HDF5 themselves, so that another HDF5
// file, such as VTKHDF or XDMF's heavy data, is not taken for either).
#include <fcntl.h>
#include <hdf5.h>
#include <netcdf.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <vector>

#include "io/readers.h"

namespace tetstream::vtkio {

namespace {

constexpr char kHdf5Signature[8] = {'\x89', 'H', 'D', 'F', '\r', '\n', '\x1a', '\n'};

// HDF5 turns its error stack printing back on for nothing; while we probe or read, a damaged
// file must not print to stderr. Restores the previous setting on scope exit.
class QuietHdf5 {
 public:
  QuietHdf5() {
    H5Eget_auto2(H5E_DEFAULT, &func_, &data_);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  ~QuietHdf5() { H5Eset_auto2(H5E_DEFAULT, func_, data_); }
  QuietHdf5(const QuietHdf5&) = delete;
  QuietHdf5& operator=(const QuietHdf5&) = delete;

 private:
  H5E_auto2_t func_ = nullptr;
  void* data_ = nullptr;
};

bool hdf5LinkExists(hid_t group, const char* name) { return H5Lexists(group, name, H5P_DEFAULT) > 0; }

// The HDF5 root of a CGNS file holds CGNSLibraryVersion; netCDF-4 keeps global attributes on the
// root group, and every Exodus II writer (the SEACAS library, meshio) sets api_version and
// stores coordinates as coordx/coordy/coordz or one coord variable.
HpcFormat hdf5Content(const std::string& path) {
  QuietHdf5 quiet;
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (file < 0) return HpcFormat::None;
  HpcFormat found = HpcFormat::None;
  const hid_t root = H5Gopen2(file, "/", H5P_DEFAULT);
  if (root >= 0) {
    if (hdf5LinkExists(root, "CGNSLibraryVersion"))
      found = HpcFormat::Cgns;
    else if (H5Aexists(root, "api_version") > 0 || hdf5LinkExists(root, "coordx") || hdf5LinkExists(root, "coord"))
      found = HpcFormat::Exodus;
    H5Gclose(root);
  }
  H5Fclose(file);
  return found;
}

HpcFormat netcdfContent(const std::string& path) {
  int ncid = -1;
  if (nc_open(path.c_str(), NC_NOWRITE, &ncid) != NC_NOERR) return HpcFormat::None;
  int id = -1;
  const bool exodus =
      nc_inq_attid(ncid, NC_GLOBAL, "api_version", &id) == NC_NOERR || nc_inq_dimid(ncid, "num_nodes", &id) == NC_NOERR;
  nc_close(ncid);
  return exodus ? HpcFormat::Exodus : HpcFormat::None;
}

// HDF5 closes whatever is still open when the program exits, and when a library left ids behind
// (the CGNS library does after failing on a damaged file: a property list it never closes) it
// prints "HDF5: infinite loop closing library" to stderr. Nothing here writes HDF5, so the exit
// handler has nothing to flush: it is not installed. This must run before any other HDF5 call,
// hence at static initialization.
const bool kNoHdf5ExitHandler = [] { return H5dont_atexit() >= 0; }();

}  // namespace

std::mutex& hpcLibraryMutex() {
  static std::mutex m;
  return m;
}

Container containerSignature(std::string_view head) {
  if (head.size() >= 4 && head.substr(0, 3) == "CDF") {
    if (head[3] == '\x01') return Container::NetcdfClassic;
    if (head[3] == '\x02') return Container::Netcdf64BitOffset;
    if (head[3] == '\x05') return Container::Netcdf64BitData;
  }
  // HDF5 looks for its superblock at 0, 512, 1024, 2048, ... (a user block may come first).
  for (size_t at = 0; at + sizeof kHdf5Signature <= head.size(); at = at ? 2 * at : 512)
    if (std::memcmp(head.data() + at, kHdf5Signature, sizeof kHdf5Signature) == 0) return Container::Hdf5;
  // ADF: "@(#)" with the high bits set, then the version text.
  if (head.size() >= 24 && head.substr(4, 20) == "ADF Database Version") return Container::Adf;
  return Container::None;
}

const char* containerName(Container c) {
  switch (c) {
    case Container::NetcdfClassic: return "netCDF classic";
    case Container::Netcdf64BitOffset: return "netCDF 64-bit offset";
    case Container::Netcdf64BitData: return "netCDF 64-bit data";
    case Container::Hdf5: return "HDF5";
    case Container::Adf: return "ADF";
    default: return "unknown container";
  }
}

HpcFormat hpcFormatByContent(const std::string& path, std::string_view head) {
  const Container c = containerSignature(head);
  if (c == Container::None) return HpcFormat::None;
  if (c == Container::Adf) return HpcFormat::Cgns;  // ADF is CGNS's own container
  std::lock_guard<std::mutex> lock(hpcLibraryMutex());
  if (c != Container::Hdf5) {
    // netCDF believes a classic header's counts: checked first. A damaged header with Exodus's
    // node count dimension in it is taken for Exodus II, whose reader then says what is wrong.
    if (!checkNetcdfClassicFile(path))
      return head.find("num_nodes") != std::string_view::npos ? HpcFormat::Exodus : HpcFormat::None;
    return netcdfContent(path);
  }
  // Exit codes 10 + the format, so that a child that ended otherwise (a sanitizer's exit code 1)
  // is not taken for an answer.
  const int found = runInChildProcess([&] { return 10 + int(hdf5Content(path)); }) - 10;
  return found == int(HpcFormat::Exodus) || found == int(HpcFormat::Cgns) ? HpcFormat(found) : HpcFormat::None;
}

int runInChildProcess(const std::function<int()>& probe) {
  std::fflush(nullptr);
  const pid_t pid = fork();
  if (pid < 0) return probe();  // no process to spare: the probe runs here
  if (pid == 0) {
    // The child: what the libraries print, or a crash report, goes nowhere.
    const int null = open("/dev/null", O_WRONLY);
    if (null >= 0) dup2(null, 1), dup2(null, 2);
    _exit(probe() & 0xFF);
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return -1;
  if (WIFSIGNALED(status)) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

bool adfDataEnd(std::string_view head, uint64_t& end) {
  // The ADF file header (ADF_internals.c): tags "AdF4" at byte 130 and "AdF5" at 182 around four
  // disk pointers of 12 hex digits each (8 for the 4096-byte block, 4 for the offset in it):
  // the root node, the end of file, the free-chunk table, reserved.
  if (head.size() < 186 || head.substr(130, 4) != "AdF4" || head.substr(182, 4) != "AdF5") return false;
  uint64_t block = 0, offset = 0;
  for (size_t i = 0; i < 12; ++i) {
    const char c = head[146 + i];
    const int digit = c >= '0' && c <= '9' ? c - '0' : c >= 'A' && c <= 'F' ? c - 'A' + 10 : -1;
    if (digit < 0) return false;
    (i < 8 ? block : offset) = (i < 8 ? block : offset) * 16 + uint64_t(digit);
  }
  end = block * 4096 + offset;
  return true;
}

void closeHdf5Leftovers(const std::string& path) {
  QuietHdf5 quiet;
  const ssize_t n = H5Fget_obj_count(H5F_OBJ_ALL, H5F_OBJ_ALL);
  if (n <= 0) return;
  std::vector<hid_t> ids(static_cast<size_t>(n));
  const ssize_t got = H5Fget_obj_ids(H5F_OBJ_ALL, H5F_OBJ_ALL, size_t(n), ids.data());
  ids.resize(size_t(std::max<ssize_t>(got, 0)));
  std::vector<hid_t> mine, files;
  for (hid_t id : ids) {
    char name[4096];
    const ssize_t len = H5Fget_name(id, name, sizeof name);
    if (len <= 0 || size_t(len) >= sizeof name || path != name) continue;
    (H5Iget_type(id) == H5I_FILE ? files : mine).push_back(id);
  }
  // Objects before their files; every reference the library left is dropped.
  for (const std::vector<hid_t>* group : {&mine, &files})
    for (hid_t id : *group)
      while (H5Iis_valid(id) > 0 && H5Idec_ref(id) > 0) {
      }
}

uint64_t maxDecodedBytes(uint64_t fileBytes, Container c) {
  // netCDF classic and ADF store arrays as they are. netCDF-4 and CGNS over HDF5 may compress
  // them, deflate by at most about 1032:1; with some slack for the smallest files.
  if (c == Container::Hdf5) return fileBytes * 1100 + (1u << 20);
  return fileBytes;
}

}  // namespace tetstream::vtkio
