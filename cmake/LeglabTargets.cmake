include(GNUInstallDirs)

# leglab_set_warnings(target): the project's warning set, applied per target. A designated
# initializer names only the fields it sets (a config key's KeyDoc); the others have their
# defaults, which GCC 12's -Wmissing-field-initializers reports all the same.
function(leglab_set_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wconversion
                                           -Wno-sign-conversion -Wnon-virtual-dtor
                                           -Wno-missing-field-initializers)
endfunction()

# leglab_set_float_options(target): floating-point options that change no result. Math
# functions need not set errno (nothing here reads it: sqrt becomes one instruction) and
# floating-point operations may be assumed not to trap (nothing here enables traps), which lets
# the compiler schedule the model code's data-dependent branches as selects. Neither reorders,
# contracts or approximates an operation (unlike -ffast-math): `track`'s and `identify`'s
# outputs are byte for byte the same with and without them, and the model code runs faster
# (docs/performance.md, "Compiler options").
function(leglab_set_float_options target)
  if(CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
    target_compile_options(${target} PRIVATE -fno-math-errno -fno-trapping-math)
  endif()
endfunction()

# leglab_add_library(<name> [INTERFACE] [SOURCES <files...>] [PUBLIC <deps...>]
#                    [PRIVATE <deps...>])
# One folder's library: leglab_<name> with the alias leglab::<name>, the folder's include/ as
# its public headers, C++20, the project's warnings and float options. INTERFACE makes a
# header-only library (no SOURCES, no PRIVATE). List only the dependencies it uses.
# Installed: the library into the export set leglabTargets as leglab::<name>, and the folder's
# include/leglab/... under <prefix>/include, but for its internal/ headers. A PRIVATE dependency of a static library is still
# needed when a program links it: leglabConfig.cmake.in must find_dependency() it.
function(leglab_add_library name)
  cmake_parse_arguments(ARG "INTERFACE" "" "SOURCES;PUBLIC;PRIVATE" ${ARGN})
  set(target leglab_${name})
  if(ARG_INTERFACE)
    add_library(${target} INTERFACE)
    set(public INTERFACE)
  else()
    add_library(${target} ${ARG_SOURCES})
    target_link_libraries(${target} PRIVATE ${ARG_PRIVATE})
    leglab_set_warnings(${target})
    leglab_set_float_options(${target})
    set(public PUBLIC)
  endif()
  add_library(leglab::${name} ALIAS ${target})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${name})
  target_include_directories(${target} ${public}
    $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_compile_features(${target} ${public} cxx_std_20)
  target_link_libraries(${target} ${public} ${ARG_PUBLIC})

  install(TARGETS ${target} EXPORT leglabTargets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
    RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  # An include/leglab/<name>/internal/ folder holds headers shared between leglab's own
  # libraries (model's vector lanes, which servo uses), not part of the API: not installed.
  install(DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
          PATTERN internal EXCLUDE)
endfunction()

# leglab_add_data(<folder> <destination>): a data folder of the source tree (e.g. robots) that
# programs read at run time, as <prefix>/share/leglab/<destination> when installed and as
# <build>/share/leglab/<destination> (a symbolic link to the source folder, so edits show at
# once) in the build tree. Programs find it relative to their own executable (DataDir()), so
# the build tree mirrors the installed layout: bin/ beside share/leglab/.
function(leglab_add_data folder destination)
  set(source ${CMAKE_CURRENT_SOURCE_DIR}/${folder})
  set(link ${PROJECT_BINARY_DIR}/${LEGLAB_DATA_DIR}/${destination})
  get_filename_component(parent ${link} DIRECTORY)
  file(MAKE_DIRECTORY ${parent})
  file(CREATE_LINK ${source} ${link} SYMBOLIC)
  install(DIRECTORY ${source}/ DESTINATION ${LEGLAB_DATA_DIR}/${destination})
endfunction()
