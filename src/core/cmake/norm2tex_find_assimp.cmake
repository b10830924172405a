# Finds assimp and sets NORM2TEX_ASSIMP_TARGET to a target that links it.
#
# assimp's own CMake target is used when it is sound. Some releases ship a broken one: 5.0.1's
# config (Ubuntu 20.04, Debian 11) derives its prefix four levels above
# <libdir>/cmake/assimp-5.0, so on a multiarch layout the target names /usr/lib/include and
# configure fails with "Imported target assimp::assimp includes non-existent path". Its
# assimp.pc has the right paths, so then pkg-config is used instead. What is checked is the
# target itself (its include directories and library files exist), not the distribution.

set(NORM2TEX_ASSIMP_TARGET "")
find_package(assimp QUIET CONFIG)

set(_norm2tex_assimp_problem "")
if(TARGET assimp::assimp)
  get_target_property(_norm2tex_assimp_includes assimp::assimp INTERFACE_INCLUDE_DIRECTORIES)
  foreach(_dir IN LISTS _norm2tex_assimp_includes)
    if(_dir AND NOT IS_DIRECTORY "${_dir}")
      set(_norm2tex_assimp_problem "include directory ${_dir} does not exist")
    endif()
  endforeach()
  get_target_property(_norm2tex_assimp_configs assimp::assimp IMPORTED_CONFIGURATIONS)
  if(NOT _norm2tex_assimp_configs)
    set(_norm2tex_assimp_configs "")
  endif()
  foreach(_prop IN ITEMS IMPORTED_LOCATION IMPORTED_IMPLIB)
    foreach(_config "" ${_norm2tex_assimp_configs})
      if(_config)
        string(TOUPPER "_${_config}" _config)
      endif()
      get_target_property(_file assimp::assimp ${_prop}${_config})
      if(_file AND NOT EXISTS "${_file}")
        set(_norm2tex_assimp_problem "library ${_file} does not exist")
      endif()
    endforeach()
  endforeach()
  if(NOT _norm2tex_assimp_problem)
    set(NORM2TEX_ASSIMP_TARGET assimp::assimp)
  endif()
else()
  set(_norm2tex_assimp_problem "no assimp::assimp target (assimp ${assimp_VERSION})")
endif()

if(NOT NORM2TEX_ASSIMP_TARGET)
  find_package(PkgConfig QUIET)
  if(PKG_CONFIG_FOUND)
    pkg_check_modules(NORM2TEX_ASSIMP_PC QUIET IMPORTED_TARGET assimp)
  endif()
  if(NORM2TEX_ASSIMP_PC_FOUND)
    set(NORM2TEX_ASSIMP_TARGET PkgConfig::NORM2TEX_ASSIMP_PC)
    message(STATUS "assimp ${NORM2TEX_ASSIMP_PC_VERSION} through pkg-config: its CMake target "
      "is unusable (${_norm2tex_assimp_problem})")
  else()
    message(FATAL_ERROR "assimp not found: its CMake target is unusable "
      "(${_norm2tex_assimp_problem}) and pkg-config finds no assimp.pc. "
      "Install libassimp-dev (rosdep key assimp).")
  endif()
else()
  message(STATUS "assimp ${assimp_VERSION} through its CMake target")
endif()
