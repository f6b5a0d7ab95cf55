# Sources of the multicor_dem library (paths relative to src/).
set(MULTICOR_DEM_SOURCES
    ${CMAKE_CURRENT_LIST_DIR}/particles.f90)
