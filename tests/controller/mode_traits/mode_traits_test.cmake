# ctest Controllers.ModeTraitsAreCheckedAtCompileTime: mode.cc compiled once per case
# (-fsyntax-only). Case 0 must compile; each other case must fail with its expected message.
# Variables: CXX (the compiler), SOURCE_DIR (the project's), EIGEN (Eigen's include folder).
set(includes -I${SOURCE_DIR}/core/include -I${SOURCE_DIR}/model/include
             -I${SOURCE_DIR}/controller/include -I${EIGEN})
set(expected
    "0|"
    "1|feed_forwrd"
    "2|kFeedForward is kTraits.feed_forward"
    "3|kTraits.has_walk_models must say whether the mode has static bool ModelFittedToWalk"
    "4|kTraits.has_parameters must say whether the mode has static"
    "5|needs static constexpr ControllerModeTraits kTraits")
foreach(entry IN LISTS expected)
  string(REPLACE "|" ";" parts "${entry}")
  list(GET parts 0 case)
  list(LENGTH parts n)
  execute_process(
    COMMAND ${CXX} -std=c++20 -fsyntax-only -DCASE=${case} ${includes}
            ${SOURCE_DIR}/tests/controller/mode_traits/mode.cc
    RESULT_VARIABLE status ERROR_VARIABLE errors OUTPUT_VARIABLE output)
  if(n EQUAL 1)
    if(NOT status EQUAL 0)
      message(FATAL_ERROR "case ${case} (a well-formed mode) does not compile:\n${errors}")
    endif()
  else()
    list(GET parts 1 needle)
    string(FIND "${errors}" "${needle}" at)
    if(status EQUAL 0 OR at EQUAL -1)
      message(FATAL_ERROR "case ${case}: expected a failure naming '${needle}', got status "
                          "${status}:\n${errors}")
    endif()
  endif()
endforeach()
