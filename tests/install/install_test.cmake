# ctest Install.Consumer (see CMakeLists.txt here). Variables: BUILD_DIR (the leglab build),
# WORK_DIR (scratch, removed before and after a passing run; left for inspection on failure),
# CONSUMER_DIR, GENERATOR, CXX_COMPILER, BUILD_TYPE, CXX_FLAGS and EXE_LINKER_FLAGS (the
# consumer is compiled as leglab was, sanitizers included), PROGRAMS (experiments built),
# BINDIR, DATADIR (relative to the prefix), PYTHON (the interpreter, empty when the Python
# package is not built) and PYTHON_DIR (its folder, relative to the prefix).

# run(<var> <command...>): runs the command, fails the test unless it exits 0; its standard
# output and error go to <var>.
function(run var)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out
                  WORKING_DIRECTORY ${WORK_DIR})
  if(NOT rc EQUAL 0)
    list(JOIN ARGN " " command)
    message(FATAL_ERROR "exit status ${rc}: ${command}\n${out}")
  endif()
  set(${var} "${out}" PARENT_SCOPE)
endfunction()

function(expect text regex what)
  if(NOT text MATCHES "${regex}")
    message(FATAL_ERROR "${what}: expected '${regex}' in:\n${text}")
  endif()
endfunction()

file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})
set(prefix ${WORK_DIR}/prefix)

run(out ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})
# Headers under an include/leglab/<library>/internal/ folder are shared between leglab's own
# libraries, not part of the API: none is installed.
file(GLOB_RECURSE internal_headers LIST_DIRECTORIES true ${prefix}/include/*)
list(FILTER internal_headers INCLUDE REGEX "/internal(/|$)")
if(internal_headers)
  message(FATAL_ERROR "internal headers installed: ${internal_headers}")
endif()

run(out ${CMAKE_COMMAND} -S ${CONSUMER_DIR} -B ${WORK_DIR}/build -G ${GENERATOR}
        -D CMAKE_PREFIX_PATH=${prefix} -D CMAKE_CXX_COMPILER=${CXX_COMPILER}
        -D CMAKE_BUILD_TYPE=${BUILD_TYPE} -D "CMAKE_CXX_FLAGS=${CXX_FLAGS}"
        -D "CMAKE_EXE_LINKER_FLAGS=${EXE_LINKER_FLAGS}")
run(out ${CMAKE_COMMAND} --build ${WORK_DIR}/build)
run(out ${WORK_DIR}/build/consumer ${prefix}/${DATADIR}/robots/ers210a/leg.urdf)
# C_m by hand (eq. 6, m = 1): the six speeds f(C - 4) .. f(C - 9) are all on the linear part
# of f, so S(C) = (2.5 / 7) (C - 6.5) = 1 gives C = 9.3.
expect("${out}" "C_m = 9\\.3000 deg" "consumer, the model")
# A 10 deg request, 25 ticks: about 5 of lag and 4 at top speed; the servo holds near 10.
expect("${out}" "rotator = (9\\.[5-9]|10\\.[0-4]) deg" "consumer, the sim")
# The real servo logs are installed as data, with their NOTICE: 12 + 4 JSON files.
file(GLOB_RECURSE logs ${prefix}/${DATADIR}/data/servo_logs/*.json)
list(LENGTH logs log_count)
if(NOT log_count EQUAL 16 OR NOT EXISTS ${prefix}/${DATADIR}/data/servo_logs/NOTICE)
  message(FATAL_ERROR "installed data/servo_logs: ${log_count} JSON files (expected 16) "
                      "or no NOTICE")
endif()

if(PROGRAMS)
  run(out ${prefix}/${BINDIR}/identify --help)
  expect("${out}" "--config" "identify --help")
  # The installed identify and config, run from a folder with no robots/: robot ers210a is
  # found beside the program (<prefix>/share/leglab), not in the source tree.
  run(out ${prefix}/${BINDIR}/identify
          --config ${prefix}/${DATADIR}/experiments/configs/identify.yaml --out ${WORK_DIR}/out
          --set identify.settle_cycles=1 --set identify.record_cycles=1)
  if(NOT EXISTS ${WORK_DIR}/out/table1.json)
    message(FATAL_ERROR "installed identify wrote no table1.json:\n${out}")
  endif()
endif()

if(PYTHON)
  # The installed package, from outside the source and build trees and without
  # LEGLAB_DATA_DIR: it finds <prefix>/share/leglab relative to itself.
  set(ENV{PYTHONPATH} ${prefix}/${PYTHON_DIR})
  unset(ENV{LEGLAB_DATA_DIR})
  # (No semicolons: the code goes through run()'s argument list.)
  run(out ${PYTHON} -c "
import os
import leglab
p = leglab.Plant(leglab.config_path('track.yaml'))
print(os.path.dirname(leglab.__file__))
print(leglab.data_dir())
print('measured', p.run([[10.0, 0.0, 20.0]] * 25)['measured'][-1])
")
  expect("${out}" "${prefix}/${PYTHON_DIR}/leglab" "the installed package's folder")
  expect("${out}" "${prefix}/${DATADIR}" "the installed package's data")
  expect("${out}" "measured \\[ *(9\\.[5-9]|10\\.[0-4])" "the installed package's plant")
  # leglab.results and leglab.servo.learned are installed; the results reader finds the output
  # declarations installed with the data (<prefix>/share/leglab/docs/outputs.md), and report
  # runs on the installed identify's folder.
  run(out ${PYTHON} -c "
import leglab.results.animate, leglab.results.compare_engines, leglab.results.plot_figures
import leglab.results.plot_logs, leglab.results.plot_sweep, leglab.results.report
import leglab.servo.learned
from leglab.results import reader
print('declarations', reader.OUTPUTS_MD, len(reader.declared_tables()))
")
  expect("${out}" "declarations ${prefix}/${DATADIR}/docs/outputs.md [1-9]"
         "the installed results reader's declarations")
  if(PROGRAMS)
    run(out ${PYTHON} -m leglab.results.report ${WORK_DIR}/out)
    expect("${out}" "report.py: 1 page" "the installed results page")
  endif()
endif()

file(REMOVE_RECURSE ${WORK_DIR})
