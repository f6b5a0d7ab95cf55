# Fail when a Fortran source is not formatted as fprettify would format it (STYLE.md 5):
# indent 4, 132 columns. Inputs: FPRETTIFY (the program), ROOT (the source tree).
# fypp sources (src/**/*.fypp, tests/pfunit_fallback/*.fypp) too: fprettify indents the body of
# each #:for / #:if block.
# To fix: fprettify -i 4 -l 132 -r src bench tests/pfunit_fallback, and fprettify -i 4 -l 132
# src/io/hdf5_file.fypp tests/pfunit_fallback/funit.fypp (-r picks Fortran extensions only).
# One fprettify process for all files (not one Python start-up per file).
file(GLOB_RECURSE sources ${ROOT}/src/*.f90 ${ROOT}/src/*.fypp ${ROOT}/bench/*.f90
    ${ROOT}/tests/pfunit_fallback/*.f90 ${ROOT}/tests/pfunit_fallback/*.fypp)
execute_process(COMMAND ${FPRETTIFY} -i 4 -l 132 --diff ${sources}
    OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
list(LENGTH sources n)
# --diff prints a unified diff per file that would change ('--- <file>' header).
string(REGEX MATCHALL "(^|\n)--- [^\n]*" bad "${out}")
if(NOT rc EQUAL 0 OR NOT out STREQUAL "")
    message("${out}${err}")
    string(REPLACE "\n--- " "" bad "${bad}")
    string(REPLACE "--- " "" bad "${bad}")
    string(REPLACE ";" "\n  " bad "${bad}")
    message(FATAL_ERROR "not formatted (run fprettify -i 4 -l 132 on them):\n  ${bad}")
endif()
message(STATUS "${n} Fortran sources formatted")
