# Sources of the multicor_coupling library (Arlequin DEM-FEM coupling).
set(MULTICOR_COUPLING_SOURCES
    ${CMAKE_CURRENT_LIST_DIR}/weights.f90
    ${CMAKE_CURRENT_LIST_DIR}/map.f90
    ${CMAKE_CURRENT_LIST_DIR}/operator.f90
    ${CMAKE_CURRENT_LIST_DIR}/lambda.f90
    ${CMAKE_CURRENT_LIST_DIR}/multiplier_space.f90
    ${CMAKE_CURRENT_LIST_DIR}/overlap2d.f90
    ${CMAKE_CURRENT_LIST_DIR}/locate2d.f90
    ${CMAKE_CURRENT_LIST_DIR}/operator2d.f90
    ${CMAKE_CURRENT_LIST_DIR}/weighted2d.f90
    ${CMAKE_CURRENT_LIST_DIR}/bilateral.f90
    ${CMAKE_CURRENT_LIST_DIR}/fe_accounts.f90
    ${CMAKE_CURRENT_LIST_DIR}/coupled_step.f90
    ${CMAKE_CURRENT_LIST_DIR}/arlequin.f90
    ${CMAKE_CURRENT_LIST_DIR}/arlequin2d.f90)
