# niftilib's nifti2_io (Debian's libnifti2-dev: NIfTI-1, NIfTI-2 and ANALYZE 7.5) as the
# imported target splat::nifti. Debian's own
# NIFTIConfig.cmake names /usr/lib instead of the multiarch folder, so the library is found
# by hand. Used by the build and by the installed package config.
if(NOT TARGET splat::nifti)
  find_path(SPLAT_NIFTI2_INCLUDE_DIR nifti2_io.h PATH_SUFFIXES nifti)
  find_library(SPLAT_NIFTI2_LIBRARY nifti2)
  find_library(SPLAT_NIFTI_ZNZ_LIBRARY znz)
  if(NOT SPLAT_NIFTI2_INCLUDE_DIR OR NOT SPLAT_NIFTI2_LIBRARY OR NOT SPLAT_NIFTI_ZNZ_LIBRARY)
    message(FATAL_ERROR "splat needs niftilib (Debian: apt-get install libnifti2-dev)")
  endif()
  add_library(splat::nifti INTERFACE IMPORTED)
  set_target_properties(splat::nifti PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${SPLAT_NIFTI2_INCLUDE_DIR}"
    INTERFACE_LINK_LIBRARIES "${SPLAT_NIFTI2_LIBRARY};${SPLAT_NIFTI_ZNZ_LIBRARY}")
endif()
