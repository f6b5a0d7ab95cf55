# Sources of the multicor_dem library (paths relative to src/).
set(MULTICOR_DEM_SOURCES
    ${CMAKE_CURRENT_LIST_DIR}/random.f90
    ${CMAKE_CURRENT_LIST_DIR}/particles.f90
    ${CMAKE_CURRENT_LIST_DIR}/generators.f90
    ${CMAKE_CURRENT_LIST_DIR}/walls.f90
    ${CMAKE_CURRENT_LIST_DIR}/materials.f90
    ${CMAKE_CURRENT_LIST_DIR}/activation.f90
    ${CMAKE_CURRENT_LIST_DIR}/contacts.f90
    ${CMAKE_CURRENT_LIST_DIR}/detection.f90
    ${CMAKE_CURRENT_LIST_DIR}/bipotential.f90
    ${CMAKE_CURRENT_LIST_DIR}/bonds.f90
    ${CMAKE_CURRENT_LIST_DIR}/nlgs.f90
    ${CMAKE_CURRENT_LIST_DIR}/bonded_block.f90
    ${CMAKE_CURRENT_LIST_DIR}/local_problem.f90
    ${CMAKE_CURRENT_LIST_DIR}/moreau_jean.f90)
