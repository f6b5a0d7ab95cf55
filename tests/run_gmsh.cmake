# Mesh a Gmsh .geo in 2D and write it as format 4.1 ASCII (a fixture of the reader tests).
# Inputs: GMSH (the program, empty when not found), GEO (input), MSH (output file).
if(NOT GMSH)
    message(FATAL_ERROR "gmsh not found: install it (Debian: apt-get install gmsh; "
        "scripts/bootstrap.sh does it) and reconfigure")
endif()
get_filename_component(dir ${MSH} DIRECTORY)
file(MAKE_DIRECTORY ${dir})
file(REMOVE ${MSH})
execute_process(COMMAND ${GMSH} -2 -format msh41 ${GEO} -o ${MSH}
    OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
if(NOT rc EQUAL 0 OR NOT EXISTS ${MSH})
    message(FATAL_ERROR "gmsh failed on ${GEO} (exit ${rc}):\n${out}${err}")
endif()
message(STATUS "${MSH} written by ${GMSH}")
