# Fail when a Fortran source is not formatted as fprettify would format it (STYLE.md 5):
# indent 4, 132 columns. Inputs: FPRETTIFY (the program), ROOT (the source tree).
# fypp sources (src/**/*.fypp) too: fprettify indents the body of each #:for / #:if block.
# To fix: fprettify -i 4 -l 132 -r src bench tests/pfunit_fallback, and fprettify -i 4 -l 132
# src/io/hdf5_file.fypp (-r picks Fortran extensions only).
file(GLOB_RECURSE sources ${ROOT}/src/*.f90 ${ROOT}/src/*.fypp ${ROOT}/bench/*.f90
    ${ROOT}/tests/pfunit_fallback/*.f90)
set(bad "")
foreach(f IN LISTS sources)
    execute_process(COMMAND ${FPRETTIFY} -i 4 -l 132 --diff ${f}
        OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
    if(NOT rc EQUAL 0 OR NOT out STREQUAL "")
        message("${out}${err}")
        list(APPEND bad ${f})
    endif()
endforeach()
list(LENGTH sources n)
if(bad)
    string(REPLACE ";" "\n  " bad "${bad}")
    message(FATAL_ERROR "not formatted (run fprettify -i 4 -l 132 on them):\n  ${bad}")
endif()
message(STATUS "${n} Fortran sources formatted")
