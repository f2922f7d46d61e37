# hypre (Debian libhypre-dev) and the MPI it is built against (Debian libopenmpi-dev): the
# pressure Poisson solve through hypre's structured-grid interface (fluid/hypre_struct_solver.cpp).
# Both are linked PRIVATELY into meniscus_fluid: no MPI or hypre header appears in a public header.

# FindMPI's C component needs the C language (the project is otherwise C++ only): hypre is a C
# library and we call MPI's C API only.
enable_language(C)
find_package(MPI COMPONENTS C)
if(NOT MPI_C_FOUND)
  message(FATAL_ERROR "MPI (C) not found: install the Debian package libopenmpi-dev "
                      "(apt-get install libopenmpi-dev, or run ./dev.sh, which installs it)")
endif()

# C++ code that includes <mpi.h> would otherwise get Open MPI's deprecated C++ bindings and
# need libmpi_cxx; we use the C API only.
set_property(TARGET MPI::MPI_C APPEND PROPERTY INTERFACE_COMPILE_DEFINITIONS
             OMPI_SKIP_MPICXX=1 MPICH_SKIP_MPICXX=1)

find_path(HYPRE_INCLUDE_DIR HYPRE_struct_ls.h PATH_SUFFIXES hypre)
find_library(HYPRE_LIBRARY NAMES HYPRE)
if(NOT HYPRE_INCLUDE_DIR OR NOT HYPRE_LIBRARY)
  message(FATAL_ERROR "hypre not found (HYPRE_struct_ls.h, libHYPRE): install the Debian package "
                      "libhypre-dev (apt-get install libhypre-dev, or run ./dev.sh, which "
                      "installs it)")
endif()
add_library(hypre::hypre UNKNOWN IMPORTED)
set_target_properties(hypre::hypre PROPERTIES
  IMPORTED_LOCATION "${HYPRE_LIBRARY}"
  INTERFACE_INCLUDE_DIRECTORIES "${HYPRE_INCLUDE_DIR}"
  INTERFACE_LINK_LIBRARIES MPI::MPI_C)
message(STATUS "hypre: ${HYPRE_LIBRARY} (headers ${HYPRE_INCLUDE_DIR}), MPI ${MPI_C_VERSION}")
