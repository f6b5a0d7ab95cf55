!> The complete MULTICOR deck schema: the sections declared in io_schema_common,
!> io_schema_fem, io_schema_dem, io_schema_coupling and io_schema_continuum, in documentation
!> order. A submodule of io_deck_schema, so that `multicor_schema` is reached through io_deck_schema while the section modules
!> build on its machinery.
submodule(io_deck_schema) io_deck_schema_multicor
    use io_schema_common, only: add_run, add_functions, add_time, add_output
    use io_schema_fem, only: add_beam, add_modal, add_initial
    use io_schema_dem, only: add_particles, add_walls, add_contacts, add_solver
    use io_schema_coupling, only: add_coupling
    use io_schema_continuum, only: add_continuum
    implicit none

contains

    !> The complete MULTICOR deck schema (sections in documentation order).
    module function multicor_schema() result(s)
        !> The schema.
        type(schema_t) :: s
        allocate (s%sections(0), s%keywords(0))
        call add_run(s)
        call add_beam(s)
        call add_particles(s)
        call add_walls(s)
        call add_contacts(s)
        call add_coupling(s)
        call add_continuum(s)
        call add_functions(s)
        call add_time(s)
        call add_solver(s)
        call add_modal(s)
        call add_initial(s)
        call add_output(s)
    end function multicor_schema
end submodule io_deck_schema_multicor
