# Run multicor on a malformed deck and check that it fails cleanly.
# Inputs: EXE (multicor), DECK (the deck), WORK (scratch folder).
# The deck's first line is '# expect: <regex>': the error message must match it, and must
# name the deck file. Exit code must be 1 (a crash or a signal gives something else), and
# an existing results folder must be left exactly as it was.
file(STRINGS ${DECK} first LIMIT_COUNT 1)
string(REGEX REPLACE "^# expect: *" "" expect "${first}")
if(expect STREQUAL first)
    message(FATAL_ERROR "${DECK}: first line must be '# expect: <regex>'")
endif()
get_filename_component(deck_name ${DECK} NAME)

file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK}/results)
file(WRITE ${WORK}/results/earlier.txt "earlier results\n")

foreach(mode IN ITEMS check run)
    if(mode STREQUAL check)
        set(args --check ${DECK})
    else()
        set(args ${DECK} --output ${WORK}/results)
    endif()
    execute_process(COMMAND ${EXE} ${args} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
    message(STATUS "multicor ${args} -> exit ${rc}\n${err}")
    if(NOT rc EQUAL 1)
        message(FATAL_ERROR "expected exit code 1, got '${rc}'")
    endif()
    if(NOT err MATCHES "${expect}")
        message(FATAL_ERROR "error message does not match '${expect}'")
    endif()
    if(NOT err MATCHES "${deck_name}")
        message(FATAL_ERROR "error message does not name the deck file ${deck_name}")
    endif()
endforeach()

file(GLOB left RELATIVE ${WORK}/results ${WORK}/results/*)
file(READ ${WORK}/results/earlier.txt kept)
if(NOT left STREQUAL "earlier.txt" OR NOT kept STREQUAL "earlier results\n")
    message(FATAL_ERROR "the results folder was modified: ${left}")
endif()
