// What an Exodus II file must be before SEACAS's library reads it (readers.h). The library
// believes the netCDF file: it reads whole variables into buffers sized by dimensions, and
// attributes into fixed fields, so a damaged file could make it write past them. Each check
// below was found by truncating and changing bytes of real files, or by reading the library:
//   - a netCDF classic header is walked first (checkNetcdfClassicHeader): netCDF itself
//     allocates and fills by the header's counts;
//   - netCDF opens the file (ex_open prints to stderr whatever ex_opts says when it cannot); a
//     netCDF-4 file first in a child process, as HDF5 frees wild pointers on some damaged files;
//   - the global attributes the library reads into one number hold one value;
//   - the variables the library reads whole hold what their dimensions say: eb_prop1 one id per
//     block, connectK one node id per node of each element, the number maps one id per node or
//     element, time_whole one time per step, coordinates one value per node;
//   - each block's element type name (the elem_type attribute of connectK) fits the library's
//     33-byte field (ex_get_block_param copies it without a bound).
#include <exodusII.h>
#include <netcdf.h>

#include <cstdio>

#include "io/readers.h"

namespace tetstream::vtkio {

namespace {

class SchemaCheck {
 public:
  SchemaCheck(int ncid, const std::string& path) : nc_(ncid), path_(path) {}

  Result run() {
    for (const char* a :
         {"api_version", "version", "floating_point_word_size", "file_size", "int64_status", "maximum_name_length"}) {
      size_t length = 0;
      if (nc_inq_attlen(nc_, NC_GLOBAL, a, &length) == NC_NOERR && length != 1)
        return fail(Status::Corrupt, path_ + ": the global attribute " + a + " holds " + std::to_string(length) +
                                         " values, expected 1 (damaged?)");
    }
    const uint64_t nodes = dim("num_nodes"), elements = dim("num_elem"), blocks = dim("num_el_blk");
    const uint64_t steps = dim("time_step"), dims = dim("num_dim");
    for (const auto& [var, want] : {std::pair<const char*, uint64_t>{"eb_prop1", blocks},
                                    {"eb_status", blocks},
                                    {"node_num_map", nodes},
                                    {"elem_num_map", elements},
                                    {"time_whole", steps},
                                    {"coordx", nodes},
                                    {"coordy", nodes},
                                    {"coordz", nodes},
                                    {"coord", dims * nodes},
                                    {"elem_var_tab", blocks * dim("num_elem_var")}})
      if (Result r = expectSize(var, want); !r) return r;
    for (uint64_t k = 1; k <= blocks; ++k) {
      const std::string n = std::to_string(k), conn = "connect" + n;
      if (Result r = expectSize(conn, dim(("num_el_in_blk" + n).c_str()) * dim(("num_nod_per_el" + n).c_str())); !r)
        return r;
      int var = -1;
      size_t length = 0;
      if (nc_inq_varid(nc_, conn.c_str(), &var) == NC_NOERR &&
          nc_inq_attlen(nc_, var, "elem_type", &length) == NC_NOERR && length > size_t(MAX_STR_LENGTH))
        return fail(Status::Corrupt, path_ + ": element block " + n + " (" + conn + ") has an element type name of " +
                                         std::to_string(length) + " characters; Exodus II allows " +
                                         std::to_string(MAX_STR_LENGTH));
    }
    return Result::success();
  }

 private:
  uint64_t dim(const char* name) const {
    int id = -1;
    size_t length = 0;
    if (nc_inq_dimid(nc_, name, &id) != NC_NOERR || nc_inq_dimlen(nc_, id, &length) != NC_NOERR) return 0;
    return length;
  }

  // A variable that exists must hold `want` values (the product of its dimensions' lengths).
  Result expectSize(const std::string& name, uint64_t want) const {
    int var = -1, ndims = 0;
    if (nc_inq_varid(nc_, name.c_str(), &var) != NC_NOERR) return Result::success();
    int ids[NC_MAX_VAR_DIMS];
    if (nc_inq_varndims(nc_, var, &ndims) != NC_NOERR || ndims < 0 || ndims > NC_MAX_VAR_DIMS ||
        nc_inq_vardimid(nc_, var, ids) != NC_NOERR)
      return fail(Status::Corrupt, path_ + ": cannot read the dimensions of variable '" + name + "'");
    uint64_t size = 1;
    for (int d = 0; d < ndims; ++d) {
      size_t length = 0;
      if (nc_inq_dimlen(nc_, ids[d], &length) != NC_NOERR || __builtin_mul_overflow(size, length, &size))
        return fail(Status::Corrupt, path_ + ": variable '" + name + "' has dimensions that cannot be read");
    }
    if (size != want)
      return fail(Status::Corrupt, path_ + ": variable '" + name + "' holds " + std::to_string(size) +
                                       " values where its dimensions in the Exodus II layout give " +
                                       std::to_string(want) + " (damaged?)");
    return Result::success();
  }

  int nc_;
  const std::string& path_;
};

}  // namespace

Result checkExodusFile(const std::string& path, Container& container) {
  std::string head(4096, '\0');
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return fail(Status::IoError, path + ": cannot open");
  head.resize(std::fread(head.data(), 1, head.size(), f));
  std::fclose(f);
  container = containerSignature(head);
  if (container == Container::None || container == Container::Adf)
    return fail(Status::BadMagic, path + ": not an Exodus II file: it starts with neither the netCDF (CDF) " +
                                      "nor the HDF5 signature" + (head.empty() ? " (the file is empty)" : ""));
  if (container != Container::Hdf5)
    if (Result r = checkNetcdfClassicFile(path); !r) return r;
  // netCDF-4: HDF5 reads the file's metadata as netCDF opens it; first in a child process.
  if (container == Container::Hdf5 && runInChildProcess([&] {
                                        int id = -1;
                                        if (nc_open(path.c_str(), NC_NOWRITE, &id) == NC_NOERR) nc_close(id);
                                        return 0;
                                      }) != 0)
    return fail(Status::Corrupt, path + ": damaged: the HDF5 library crashed opening it (in a separate process)");
  int ncid = -1;
  if (const int status = nc_open(path.c_str(), NC_NOWRITE, &ncid); status != NC_NOERR)
    return fail(Status::Corrupt, path + ": netCDF cannot open it (" + nc_strerror(status) + ")");
  Result r = SchemaCheck(ncid, path).run();
  nc_close(ncid);
  return r;
}

}  // namespace tetstream::vtkio
