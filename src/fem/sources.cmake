# Sources of the multicor_fem library (paths relative to src/): beams, then the 2D continuum.
set(MULTICOR_FEM_SOURCES
    ${CMAKE_CURRENT_LIST_DIR}/beam_config.f90
    ${CMAKE_CURRENT_LIST_DIR}/beam_element.f90
    ${CMAKE_CURRENT_LIST_DIR}/beam_model.f90
    ${CMAKE_CURRENT_LIST_DIR}/newmark.f90
    ${CMAKE_CURRENT_LIST_DIR}/modal.f90
    ${CMAKE_CURRENT_LIST_DIR}/static.f90
    ${CMAKE_CURRENT_LIST_DIR}/triplets.f90
    ${CMAKE_CURRENT_LIST_DIR}/elastic2d.f90
    ${CMAKE_CURRENT_LIST_DIR}/element2d.f90
    ${CMAKE_CURRENT_LIST_DIR}/element_q4.f90
    ${CMAKE_CURRENT_LIST_DIR}/element_t3.f90
    ${CMAKE_CURRENT_LIST_DIR}/edge_load.f90
    ${CMAKE_CURRENT_LIST_DIR}/mesh2d.f90
    ${CMAKE_CURRENT_LIST_DIR}/mesh_generator.f90
    ${CMAKE_CURRENT_LIST_DIR}/gmsh_reader.f90
    ${CMAKE_CURRENT_LIST_DIR}/continuum_model.f90)
