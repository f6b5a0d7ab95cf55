# FindCHOLMOD: SuiteSparse CHOLMOD (sparse Cholesky), as packaged by Debian/Ubuntu
# (libsuitesparse-dev: headers in <prefix>/include/suitesparse, libcholmod.so).
#
# Defines CHOLMOD_FOUND, CHOLMOD_INCLUDE_DIR, CHOLMOD_LIBRARY, CHOLMOD_VERSION and the imported
# target CHOLMOD::CHOLMOD. SuiteSparse >= 7 also installs a CMake package configuration: it is
# used when present (target SuiteSparse::CHOLMOD), the header search below otherwise
# (SuiteSparse 5.x, Debian 12).

if(NOT TARGET CHOLMOD::CHOLMOD)
    find_package(CHOLMOD CONFIG QUIET)
    if(TARGET SuiteSparse::CHOLMOD)
        add_library(CHOLMOD::CHOLMOD INTERFACE IMPORTED)
        set_target_properties(CHOLMOD::CHOLMOD PROPERTIES INTERFACE_LINK_LIBRARIES SuiteSparse::CHOLMOD)
        get_target_property(CHOLMOD_INCLUDE_DIR SuiteSparse::CHOLMOD INTERFACE_INCLUDE_DIRECTORIES)
        set(CHOLMOD_LIBRARY SuiteSparse::CHOLMOD)
    endif()
endif()

if(NOT TARGET CHOLMOD::CHOLMOD)
    find_path(CHOLMOD_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse)
    find_library(CHOLMOD_LIBRARY cholmod)
    find_library(CHOLMOD_SUITESPARSECONFIG_LIBRARY suitesparseconfig)
    if(CHOLMOD_INCLUDE_DIR AND EXISTS ${CHOLMOD_INCLUDE_DIR}/cholmod.h)
        # SuiteSparse 5.x keeps the version in cholmod_core.h, 7.x in cholmod.h.
        foreach(header cholmod.h cholmod_core.h)
            if(EXISTS ${CHOLMOD_INCLUDE_DIR}/${header} AND NOT CHOLMOD_VERSION)
                file(STRINGS ${CHOLMOD_INCLUDE_DIR}/${header} _cholmod_version_lines
                    REGEX "#define CHOLMOD_(MAIN|SUB|SUBSUB)_VERSION[ \t]+[0-9]+")
                foreach(part MAIN SUB SUBSUB)
                    string(REGEX MATCH "CHOLMOD_${part}_VERSION[ \t]+([0-9]+)" _m "${_cholmod_version_lines}")
                    set(_cholmod_${part} ${CMAKE_MATCH_1})
                endforeach()
                if(NOT "${_cholmod_MAIN}" STREQUAL "")
                    set(CHOLMOD_VERSION "${_cholmod_MAIN}.${_cholmod_SUB}.${_cholmod_SUBSUB}")
                endif()
            endif()
        endforeach()
    endif()
endif()

include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(CHOLMOD
    REQUIRED_VARS CHOLMOD_LIBRARY CHOLMOD_INCLUDE_DIR
    VERSION_VAR CHOLMOD_VERSION
    REASON_FAILURE_MESSAGE
        "SuiteSparse CHOLMOD is required (sparse direct solver): on Debian/Ubuntu install the package libsuitesparse-dev (apt-get install libsuitesparse-dev), or point CMAKE_PREFIX_PATH at a SuiteSparse installation")

if(CHOLMOD_FOUND AND NOT TARGET CHOLMOD::CHOLMOD)
    add_library(CHOLMOD::CHOLMOD UNKNOWN IMPORTED)
    set_target_properties(CHOLMOD::CHOLMOD PROPERTIES
        IMPORTED_LOCATION ${CHOLMOD_LIBRARY}
        INTERFACE_INCLUDE_DIRECTORIES ${CHOLMOD_INCLUDE_DIR})
    if(CHOLMOD_SUITESPARSECONFIG_LIBRARY)
        set_property(TARGET CHOLMOD::CHOLMOD APPEND PROPERTY
            INTERFACE_LINK_LIBRARIES ${CHOLMOD_SUITESPARSECONFIG_LIBRARY})
    endif()
endif()
mark_as_advanced(CHOLMOD_INCLUDE_DIR CHOLMOD_LIBRARY CHOLMOD_SUITESPARSECONFIG_LIBRARY)
