# bench_bonded's command line: --help (and -h) prints the usage and runs nothing, exit 0; a deck
# that does not exist, or does not read, is a clean error before anything runs: a message naming
# it on standard error, exit code 1, no "ERROR STOP" and no backtrace; an unknown option is a usage error,
# exit code 2. Inputs: EXE (bench_bonded), WORK (scratch folder).
# The bench programs are not part of `all` (./test.sh builds them, `cmake --build build
# --target bench` too): without bench_bonded the test reports as skipped, with the reason
# (SKIP_REGULAR_EXPRESSION in tests/CMakeLists.txt), rather than failing a user's plain build.
if(NOT EXISTS "${EXE}")
    message(STATUS "skipped: bench_bonded is not built (cmake --build <build> --target bench)")
    return()
endif()
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})

function(expect_clean what out err)
    foreach(bad IN ITEMS "ERROR STOP" "Backtrace" "# bonded block against NLGS")
        if("${out}${err}" MATCHES "${bad}")
            message(FATAL_ERROR "${what}: the output holds '${bad}' (a benchmark run or a crash)")
        endif()
    endforeach()
endfunction()

foreach(flag IN ITEMS --help -h)
    execute_process(COMMAND ${EXE} ${flag} WORKING_DIRECTORY ${WORK} TIMEOUT 60
        RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
    message(STATUS "bench_bonded ${flag} -> exit ${rc}\n${out}${err}")
    if(NOT rc EQUAL 0)
        message(FATAL_ERROR "bench_bonded ${flag}: expected exit code 0, got '${rc}'")
    endif()
    if(NOT out MATCHES "usage: bench_bonded \\[deck \\[nlgs_steps\\]\\]")
        message(FATAL_ERROR "bench_bonded ${flag}: no usage on standard output")
    endif()
    expect_clean("bench_bonded ${flag}" "${out}" "${err}")
endforeach()

execute_process(COMMAND ${EXE} no_such_deck.dat WORKING_DIRECTORY ${WORK} TIMEOUT 60
    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
message(STATUS "bench_bonded no_such_deck.dat -> exit ${rc}\n${out}${err}")
if(NOT rc EQUAL 1)
    message(FATAL_ERROR "missing deck: expected exit code 1, got '${rc}'")
endif()
if(NOT err MATCHES "cannot open the deck 'no_such_deck.dat': no such file")
    message(FATAL_ERROR "missing deck: the message on standard error does not name the deck")
endif()
expect_clean("missing deck" "${out}" "${err}")

# a deck that exists but does not read: its error (file, line) before the clamped row is timed
file(WRITE ${WORK}/bad_section.dat "[foo]\n")
execute_process(COMMAND ${EXE} bad_section.dat 0 WORKING_DIRECTORY ${WORK} TIMEOUT 60
    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
message(STATUS "bench_bonded bad_section.dat 0 -> exit ${rc}\n${out}${err}")
if(NOT rc EQUAL 1)
    message(FATAL_ERROR "deck that does not read: expected exit code 1, got '${rc}'")
endif()
if(NOT err MATCHES "bad_section.dat:1: unknown section \\[foo\\]")
    message(FATAL_ERROR "deck that does not read: the message on standard error does not name file and line")
endif()
expect_clean("deck that does not read" "${out}" "${err}")

execute_process(COMMAND ${EXE} --frobnicate WORKING_DIRECTORY ${WORK} TIMEOUT 60
    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
message(STATUS "bench_bonded --frobnicate -> exit ${rc}\n${out}${err}")
if(NOT rc EQUAL 2)
    message(FATAL_ERROR "unknown option: expected exit code 2, got '${rc}'")
endif()
if(NOT err MATCHES "unknown option '--frobnicate'" OR NOT err MATCHES "usage: bench_bonded")
    message(FATAL_ERROR "unknown option: no message naming it with the usage on standard error")
endif()
expect_clean("unknown option" "${out}" "${err}")
