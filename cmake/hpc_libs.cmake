# The HPC container libraries behind the Exodus II, CGNS, XDMF and VTKHDF readers, as one
# interface target, tetstream_hpc_libs: HDF5 (serial), netCDF (Exodus II files are netCDF),
# SEACAS's Exodus II library and the CGNS library, all from Debian (scripts/setup.sh installs
# them). The readers use these libraries, not parsers of their own: the containers are complex
# (B-trees, chunked and filtered datasets, ADF and HDF5 CGNS) and the libraries are what the
# writers use.
#
# Debian has no static netCDF, and static HDF5 needs curl and OpenSSL's archives, so a program
# that links these is linked to them dynamically, the CLI included.
pkg_check_modules(HDF5 REQUIRED IMPORTED_TARGET hdf5-serial)
pkg_check_modules(NETCDF REQUIRED IMPORTED_TARGET netcdf)
find_library(TETSTREAM_EXODUS_LIBRARY NAMES exoIIv2c exodus REQUIRED)
find_path(TETSTREAM_EXODUS_INCLUDE exodusII.h REQUIRED)
find_library(TETSTREAM_CGNS_LIBRARY NAMES cgns REQUIRED)
find_path(TETSTREAM_CGNS_INCLUDE cgnslib.h REQUIRED)

add_library(tetstream_hpc_libs INTERFACE)
target_include_directories(tetstream_hpc_libs SYSTEM INTERFACE ${TETSTREAM_EXODUS_INCLUDE} ${TETSTREAM_CGNS_INCLUDE})
target_link_libraries(tetstream_hpc_libs INTERFACE ${TETSTREAM_EXODUS_LIBRARY} ${TETSTREAM_CGNS_LIBRARY}
                      PkgConfig::NETCDF PkgConfig::HDF5)
