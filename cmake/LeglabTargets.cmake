# leglab_set_warnings(target): the project's warning set, applied per target.
function(leglab_set_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wconversion
                                           -Wno-sign-conversion -Wnon-virtual-dtor)
endfunction()

# leglab_add_library(<name> SOURCES <files...> [PUBLIC <deps...>] [PRIVATE <deps...>])
# One folder's library: leglab_<name> with the alias leglab::<name>, the folder's include/ as
# its public headers, C++20 and the project's warnings. List only the dependencies it uses.
function(leglab_add_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;PUBLIC;PRIVATE" ${ARGN})
  add_library(leglab_${name} ${ARG_SOURCES})
  add_library(leglab::${name} ALIAS leglab_${name})
  target_include_directories(leglab_${name} PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/include)
  target_compile_features(leglab_${name} PUBLIC cxx_std_20)
  target_link_libraries(leglab_${name} PUBLIC ${ARG_PUBLIC} PRIVATE ${ARG_PRIVATE})
  leglab_set_warnings(leglab_${name})
endfunction()
