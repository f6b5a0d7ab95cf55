# Check that the deck reference in doc/input.md is the one generated from the schema.
# Inputs: EXE (multicor), DOC (doc/input.md); optional UPDATE=ON rewrites DOC instead.
# The text between the lines '<!-- BEGIN SCHEMA -->' and '<!-- END SCHEMA -->' must equal
# the output of `multicor --schema-markdown` exactly.
cmake_policy(SET CMP0007 NEW)
set(begin_marker "<!-- BEGIN SCHEMA -->\n")
set(end_marker "<!-- END SCHEMA -->")

execute_process(COMMAND ${EXE} --schema-markdown
    RESULT_VARIABLE rc OUTPUT_VARIABLE generated ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${EXE} --schema-markdown failed (exit ${rc}):\n${err}")
endif()

file(READ ${DOC} doc)
string(REPLACE "\r\n" "\n" doc "${doc}")
string(FIND "${doc}" "${begin_marker}" begin_pos)
string(FIND "${doc}" "${end_marker}" end_pos)
if(begin_pos EQUAL -1 OR end_pos EQUAL -1)
    message(FATAL_ERROR "${DOC}: the markers '<!-- BEGIN SCHEMA -->' and '<!-- END SCHEMA -->' "
        "must each stand on a line of their own")
endif()
string(LENGTH "${begin_marker}" begin_len)
math(EXPR start "${begin_pos} + ${begin_len}")
math(EXPR length "${end_pos} - ${start}")
if(length LESS 0)
    message(FATAL_ERROR "${DOC}: '<!-- END SCHEMA -->' comes before '<!-- BEGIN SCHEMA -->'")
endif()
string(SUBSTRING "${doc}" ${start} ${length} documented)

if(documented STREQUAL generated)
    message(STATUS "${DOC}: the deck reference matches the schema")
    return()
endif()

set(regenerate "cmake -DEXE=${EXE} -DDOC=${DOC} -DUPDATE=ON -P ${CMAKE_CURRENT_LIST_FILE}")
if(UPDATE)
    string(SUBSTRING "${doc}" 0 ${start} head)
    string(SUBSTRING "${doc}" ${end_pos} -1 tail)
    file(WRITE ${DOC} "${head}${generated}${tail}")
    message(STATUS "${DOC}: deck reference regenerated from the schema")
    return()
endif()

# First differing line, for the hint. Protect ';' and brackets from CMake's list splitting.
foreach(var IN ITEMS documented generated)
    string(REPLACE ";" "<semicolon>" ${var} "${${var}}")
    string(REPLACE "[" "<lbracket>" ${var} "${${var}}")
    string(REPLACE "]" "<rbracket>" ${var} "${${var}}")
    string(REPLACE "\n" ";" ${var}_lines "${${var}}")
endforeach()
list(LENGTH documented_lines n_documented)
list(LENGTH generated_lines n_generated)
set(i 0)
while(i LESS n_documented AND i LESS n_generated)
    list(GET documented_lines ${i} a)
    list(GET generated_lines ${i} b)
    if(NOT a STREQUAL b)
        break()
    endif()
    math(EXPR i "${i} + 1")
endwhile()
set(a "(end of the reference)")
set(b "(end of the reference)")
if(i LESS n_documented)
    list(GET documented_lines ${i} a)
endif()
if(i LESS n_generated)
    list(GET generated_lines ${i} b)
endif()
foreach(var IN ITEMS a b)
    string(REPLACE "<semicolon>" ";" ${var} "${${var}}")
    string(REPLACE "<lbracket>" "[" ${var} "${${var}}")
    string(REPLACE "<rbracket>" "]" ${var} "${${var}}")
endforeach()
string(SUBSTRING "${doc}" 0 ${start} head)
string(REGEX MATCHALL "\n" newlines "${head}")
list(LENGTH newlines line)
math(EXPR line "${line} + ${i} + 1")
message(FATAL_ERROR "${DOC} is out of date with the deck schema (src/io/deck_schema.f90).\n"
    "First difference at ${DOC}:${line}:\n"
    "  in the doc:  ${a}\n"
    "  generated:   ${b}\n"
    "Regenerate the reference with:\n  ${regenerate}")
