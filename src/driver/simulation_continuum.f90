!> 2D continuum runs: a [continuum] deck (no [beam], no [particles]). What the static, modal
!> and dynamic analyses share is here: the mesh, the materials, the supports, the loads and the
!> operators K and M on the free dofs, built from the deck. Each analysis is an extension in its
!> own module (driver_simulation_continuum_static, _modal and _dynamic); `driver_simulations`
!> picks it from `[run] analysis`.
!>
!> The mesh comes from the rectangle generator or a Gmsh file; the deck's named sets are the
!> mesh's (a Gmsh mesh gets the sets 'all' of its nodes and elements as well). Static: K_ff
!> u_f = f_f - K_fp u_p by CHOLMOD. Modal: band LAPACK (dsbgvx) on the reduced K and M. Dynamic:
!> the integrators of fem_newmark on the continuum as a `dynamic_operator_t`, with checkpoints
!> and restart as the beam's (driver_checkpoint: the integrator's state and the results file's
!> record counts).
module driver_simulation_continuum
    use core_kinds, only: wp, i8
    use core_error, only: error_t, make_input_error, make_internal_error
    use core_strings, only: string_t, to_str, quoted_name, same_name
    use io_deck, only: deck_t, deck_entry_t
    use fem_mesh2d, only: mesh2d_t
    use fem_mesh_generator, only: rectangle_mesh, rectangle_size, check_rectangle_size
    use fem_element_registry, only: element_slot_t, new_element, kind_of_name
    use fem_gmsh_reader, only: read_gmsh
    use io_paths, only: read_file_text
    use fem_elastic2d, only: elastic2d_t, make_elastic2d
    use fem_continuum_model, only: continuum_model_t
    use fem_continuum_dynamics, only: continuum_dynamics_t
    use fem_mass_scheme, only: mass_scheme_t, make_mass_scheme
    use driver_config, only: build_run_settings
    use driver_config_timefunc, only: build_time_functions
    use driver_checkpoint, only: deck_hash
    use driver_simulation, only: simulation_t
    use driver_run_kind, only: check_particle_keywords_unused, check_initial_unused
    use driver_model_size, only: size_estimate_t, model_size_t
    implicit none
    private
    public :: continuum_simulation_t, continuum_setup, check_density

    !> A 2D continuum run; its analysis is the extension.
    type, abstract, extends(simulation_t) :: continuum_simulation_t
        !> The continuum (mesh, materials, loads, prescribed dofs).
        type(continuum_model_t) :: model
        !> K, M and loads on the free dofs.
        type(continuum_dynamics_t) :: ops
        !> Deck file.
        character(len=:), allocatable :: deck_file
        !> Hash of the Gmsh mesh file's text ('' for a generated mesh), for the checkpoints.
        character(len=:), allocatable :: mesh_hash
    contains
        !> See `simulation_t%describe`.
        procedure :: describe => continuum_describe
        !> See `simulation_t%checkpoint_kind`: none (the dynamic analysis writes them).
        procedure :: checkpoint_kind => continuum_checkpoint_kind
        !> See `simulation_t%has_time_loop`: no (the dynamic analysis has one).
        procedure :: has_time_loop => continuum_has_time_loop
        !> See `simulation_t%check_deck`: no particle settings, no [initial].
        procedure :: check_deck => continuum_check_deck
        !> See `simulation_t%deck_warnings`: none.
        procedure :: deck_warnings => continuum_deck_warnings
        !> See `simulation_t%size_estimate`: the elements of a rectangle mesh.
        procedure :: size_estimate => continuum_size_estimate
        !> See `simulation_t%inputs_text`: the Gmsh mesh file.
        procedure :: inputs_text => continuum_inputs_text
    end type continuum_simulation_t

contains

    !> Mesh, model, boundary conditions, loads, operators and run settings from the deck: the
    !> start of every analysis' `init` (which adds what its analysis needs).
    subroutine continuum_setup(self, deck, error)
        !> The simulation.
        class(continuum_simulation_t), intent(inout) :: self
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        !> Set on any input error.
        type(error_t), allocatable, intent(out) :: error
        type(mesh2d_t) :: mesh
        type(deck_entry_t) :: e
        type(deck_entry_t), allocatable :: list(:)
        character(len=:), allocatable :: message
        ! Deck ids of the time functions; constant loads set aside while a timed one is added.
        integer, allocatable :: function_ids(:)
        real(wp), allocatable :: constant(:)
        class(mass_scheme_t), allocatable :: mass
        integer :: n_free
        integer, allocatable :: eq(:)
        self%deck_file = deck%file
        call build_mesh(error)
        if (allocated(error)) return
        call self%model%init(mesh, error)
        if (allocated(error)) call fail_at(error, deck%line('continuum', 'mesh'), 'mesh')
        if (allocated(error)) return
        call set_materials(error)
        if (allocated(error)) return
        call build_time_functions(deck, self%model%functions, function_ids, error)
        if (allocated(error)) return
        call set_constraints(error)
        if (allocated(error)) return
        call set_loads(error)
        if (allocated(error)) return
        call self%model%equations(eq, n_free)
        if (n_free == 0) then
            call make_input_error(error, deck%file, deck%line('continuum', 'fix'), 'fix', &
                                  'every dof of the continuum is prescribed: nothing to solve')
            return
        end if
        call make_mass_scheme(deck%get_word('continuum', 'mass'), mass, error)
        if (allocated(error)) return
        call self%ops%build(self%model, mass, deck%get_real('continuum', 'rayleigh', 'a0'), &
                            deck%get_real('continuum', 'rayleigh', 'a1'), error)
        if (allocated(error)) call fail_at(error, deck%line('continuum', 'mesh'), 'mesh')
        if (allocated(error)) return
        call build_run_settings(deck, self%ops%n_free, mass, 'continuum', self%settings, error)
        if (allocated(error)) return

    contains

        !> Input error at a line (keeps the library's message).
        subroutine fail_at(error, at, keyword)
            type(error_t), allocatable, intent(inout) :: error
            integer, intent(in) :: at
            character(len=*), intent(in) :: keyword
            message = error%message
            call make_input_error(error, deck%file, at, keyword, message)
        end subroutine fail_at

        !> The mesh: generated rectangle or Gmsh file (relative to the deck's folder).
        subroutine build_mesh(error)
            type(error_t), allocatable, intent(out) :: error
            character(len=:), allocatable :: path, text
            type(element_slot_t) :: element
            integer :: i
            if (.not. deck%has('continuum', 'mesh')) then
                call make_input_error(error, deck%file, first_line(), 'mesh', '[continuum] needs a mesh: '// &
                                      'mesh = rectangle x0 y0 lx ly nx ny q4|t3, or mesh = file <name>.msh')
                return
            end if
            e = deck%record('continuum', 'mesh', 1)
            if (e%word('kind') == 'rectangle') then
                ! The schema admits only the names of registered element kinds.
                call new_element(kind_of_name(e%word('element')), element)
                call rectangle_mesh(e%real('x0'), e%real('x0') + e%real('lx'), e%real('y0'), e%real('y0') + e%real('ly'), &
                                    e%int('nx'), e%int('ny'), element%element, mesh, error)
            else
                path = e%word('path')
                if (path(1:1) /= '/') path = folder(deck%file)//path
                call read_gmsh(path, mesh, error)
                if (.not. allocated(error)) call read_file_text(path, text, error)
                if (.not. allocated(error)) self%mesh_hash = deck_hash(text)
                if (.not. allocated(error)) then
                    if (.not. any([(same_name(mesh%element_sets(i)%name, 'all'), i=1, size(mesh%element_sets))])) &
                        call mesh%add_element_set('all', [(i, i=1, mesh%element_count())])
                    if (.not. any([(same_name(mesh%node_sets(i)%name, 'all'), i=1, size(mesh%node_sets))])) &
                        call mesh%add_node_set('all', [(i, i=1, mesh%node_count())])
                end if
            end if
            if (allocated(error)) call fail_at(error, e%line, 'mesh')
        end subroutine build_mesh

        !> Line of the first [continuum] entry.
        integer function first_line()
            integer :: i
            first_line = 0
            do i = 1, size(deck%entries)
                if (deck%entries(i)%section /= 'continuum' .or. deck%entries(i)%line == 0) cycle
                first_line = deck%entries(i)%line
                return
            end do
        end function first_line

        !> Materials of the element sets; every element must get one.
        subroutine set_materials(error)
            type(error_t), allocatable, intent(out) :: error
            type(elastic2d_t) :: mat
            character(len=:), allocatable :: set
            integer :: i
            list = deck%records('continuum', 'material')
            if (size(list) == 0) then
                call make_input_error(error, deck%file, first_line(), 'material', '[continuum] needs a material: '// &
                                      'material = young poisson density thickness plane_stress|plane_strain [set]')
                return
            end if
            do i = 1, size(list)
                e = list(i)
                call make_elastic2d(e%real('young'), e%real('poisson'), e%real('density'), e%real('thickness'), &
                                    e%word('hypothesis') == 'plane_strain', mat, error)
                if (allocated(error)) call fail_at(error, e%line, 'material')
                if (allocated(error)) return
                set = 'all'
                if (e%has('element_set')) set = e%word('element_set')
                call self%model%set_material(set, mat, error)
                if (allocated(error)) call fail_at(error, e%line, 'material')
                if (allocated(error)) return
            end do
            call self%model%check(error)
            if (allocated(error)) call fail_at(error, list(1)%line, 'material')
            if (allocated(error)) return
            i = self%model%unrepresentable_element()
            if (i > 0) call make_input_error(error, deck%file, list(self%model%element_material(i))%line, 'material', &
                                             'the stiffness or mass of '//self%model%mesh%element_label(i)// &
                                             ' overflows or vanishes '// &
                                             'in double precision (beyond 1.8e308 or below 2.2e-308: E t, rho t A); '// &
                                             'check the modulus, density and thickness, and the mesh''s units')
        end subroutine set_materials

        !> Supports (fix) and prescribed displacements. A dof may be prescribed by several
        !> records only with the same value and the same function (overlapping sets, e.g. the
        !> corner node of left and bottom); different ones are an error naming both lines.
        subroutine set_constraints(error)
            type(error_t), allocatable, intent(out) :: error
            type(string_t), allocatable :: components(:)
            ! Line of the record that prescribed each dof first (0: free so far).
            integer, allocatable :: by_line(:)
            integer :: i, j, func
            allocate (by_line(self%model%dof_count()), source=0)
            list = deck%records('continuum', 'fix')
            do i = 1, size(list)
                e = list(i)
                components = e%words_from('component')
                do j = 1, size(components)
                    call prescribe('fix', component(components(j)%s), 0.0_wp, 0, by_line, error)
                    if (allocated(error)) return
                end do
            end do
            list = deck%records('continuum', 'displacement')
            do i = 1, size(list)
                e = list(i)
                call find_function('displacement', func, error)
                if (allocated(error)) return
                call prescribe('displacement', component(e%word('component')), e%real('value'), func, by_line, &
                               error)
                if (allocated(error)) return
            end do
        end subroutine set_constraints

        !> Prescribe `value` times function `func` on one component of the node set of record
        !> e, refusing a dof that an earlier record prescribed otherwise (`by_line`: line of
        !> the record that prescribed each dof first, 0 for none yet).
        subroutine prescribe(keyword, comp, value, func, by_line, error)
            character(len=*), intent(in) :: keyword
            integer, intent(in) :: comp, func
            real(wp), intent(in) :: value
            integer, intent(inout) :: by_line(:)
            type(error_t), allocatable, intent(out) :: error
            integer, allocatable :: ids(:)
            integer :: k, dof
            call self%model%mesh%node_set(e%word('node_set'), ids, error)
            if (allocated(error)) call fail_at(error, e%line, keyword)
            if (allocated(error)) return
            do k = 1, size(ids)
                dof = 2*ids(k) - 2 + comp
                if (by_line(dof) == 0) then
                    by_line(dof) = e%line
                else if (self%model%prescribed_value(dof) /= value .or. &
                         self%model%prescribed_function(dof) /= func) then
                    call make_input_error(error, deck%file, e%line, keyword, 'node '//to_str(ids(k))// &
                                          ' at ('//to_str(self%model%mesh%x(1, ids(k)))//', '// &
                                          to_str(self%model%mesh%x(2, ids(k)))//') m of set '// &
                                          quoted_name(e%word('node_set'))//', component '//merge('x', 'y', comp == 1)// &
                                          ', is already prescribed by line '//to_str(by_line(dof))// &
                                          ' with another value or function: give each displacement component '// &
                                          'of a node one prescription (a repeated one must be the same value '// &
                                          'and function)')
                    return
                end if
            end do
            call self%model%prescribe_set(e%word('node_set'), comp, value, error, func)
            if (allocated(error)) call fail_at(error, e%line, keyword)
        end subroutine prescribe

        !> Nodal loads and tractions (constant, or times a [functions] function), and gravity.
        subroutine set_loads(error)
            type(error_t), allocatable, intent(out) :: error
            integer, allocatable :: ids(:)
            integer :: i, j, func
            real(wp) :: gravity(2)
            ! The loads of every record so far (constant and timed), before record e.
            real(wp), allocatable :: before(:)
            deallocate (self%model%timed_load)
            allocate (self%model%timed_load(self%model%dof_count(), size(function_ids)), source=0.0_wp)
            list = deck%records('continuum', 'load')
            do i = 1, size(list)
                e = list(i)
                call start_load('load', func, error)
                if (allocated(error)) return
                call self%model%mesh%node_set(e%word('node_set'), ids, error)
                if (allocated(error)) call fail_at(error, e%line, 'load')
                if (allocated(error)) return
                before = applied()
                do j = 1, size(ids)
                    call self%model%add_nodal_load(ids(j), component(e%word('component')), e%real('value'))
                end do
                call end_load(func)
                call require_effect('load', before, error)
                if (allocated(error)) return
            end do
            list = deck%records('continuum', 'traction')
            do i = 1, size(list)
                e = list(i)
                call start_load('traction', func, error)
                if (allocated(error)) return
                before = applied()
                if (e%word('profile') == 'parabolic') then
                    call self%model%add_traction_parabolic(e%word('edge_set'), [e%real('tx'), e%real('ty')], error)
                else
                    call self%model%add_traction(e%word('edge_set'), [e%real('tx'), e%real('ty')], error)
                end if
                if (allocated(error)) call fail_at(error, e%line, 'traction')
                if (allocated(error)) return
                call end_load(func)
                call require_effect('traction', before, error)
                if (allocated(error)) return
            end do
            gravity = [deck%get_real('continuum', 'gravity', 'gx'), deck%get_real('continuum', 'gravity', 'gy')]
            if (any(gravity /= 0)) then
                call self%model%add_body_force(gravity, error)
                if (allocated(error)) call fail_at(error, deck%line('continuum', 'gravity'), 'gravity')
                if (allocated(error)) return
            end if
        end subroutine set_loads

        !> Before adding the load of record e: its function (0 = none, constant 1) and, for a
        !> timed load, the constant loads set aside so that the model's `load` collects it alone.
        subroutine start_load(keyword, func, error)
            character(len=*), intent(in) :: keyword
            integer, intent(out) :: func
            type(error_t), allocatable, intent(out) :: error
            call find_function(keyword, func, error)
            if (allocated(error) .or. func == 0) return
            constant = self%model%load
            self%model%load = 0.0_wp
        end subroutine start_load

        !> Index among the model's functions of the function of record e (0: none).
        subroutine find_function(keyword, func, error)
            character(len=*), intent(in) :: keyword
            integer, intent(out) :: func
            type(error_t), allocatable, intent(out) :: error
            func = 0
            if (.not. e%has('function')) return
            func = findloc(function_ids, e%int('function'), dim=1)
            if (func == 0) call make_input_error(error, deck%file, e%line, keyword, 'function '//e%word('function')// &
                                                 ' is not defined (no [functions] function record with this id)')
        end subroutine find_function

        !> The loads of the records so far: the constant ones and every function's column.
        function applied() result(total)
            real(wp), allocatable :: total(:)
            total = self%model%load + sum(self%model%timed_load, dim=2)
        end function applied

        !> A load or traction record whose forces all land on prescribed dofs (fix or
        !> displacement) does nothing, like a beam's load on a support: an input error. One
        !> that also loads a free dof is fine (an edge traction on a clamped corner).
        subroutine require_effect(keyword, before, error)
            character(len=*), intent(in) :: keyword
            real(wp), intent(in) :: before(:)
            type(error_t), allocatable, intent(out) :: error
            real(wp), allocatable :: added(:)
            integer, allocatable :: eq(:)
            integer :: n
            added = applied() - before
            if (all(added == 0.0_wp)) return
            call self%model%equations(eq, n)
            if (any(added /= 0.0_wp .and. eq > 0)) return
            call make_input_error(error, deck%file, e%line, keyword, 'every force of this '//keyword// &
                                  ' lands on a prescribed dof (fix or displacement), where the support takes '// &
                                  'it: it does nothing; remove it or free those dofs')
        end subroutine require_effect

        !> After adding the load of record e: a timed load moves to its function's column.
        subroutine end_load(func)
            integer, intent(in) :: func
            if (func == 0) return
            self%model%timed_load(:, func) = self%model%timed_load(:, func) + self%model%load
            self%model%load = constant
        end subroutine end_load
    end subroutine continuum_setup

    !> Modes and dynamics need a positive-definite mass: every density > 0.
    subroutine check_density(deck, error)
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        !> Set on the first material without a density.
        type(error_t), allocatable, intent(out) :: error
        type(deck_entry_t), allocatable :: list(:)
        integer :: i
        list = deck%records('continuum', 'material')
        do i = 1, size(list)
            if (list(i)%real('density') > 0) cycle
            call make_input_error(error, deck%file, list(i)%line, 'material', 'a '// &
                                  deck%get_word('run', 'analysis')//' analysis needs a density > 0 (the mass '// &
                                  'matrix must be positive definite)')
            return
        end do
    end subroutine check_density

    !> Folder of a path, with its trailing '/' ('' for a bare name).
    pure function folder(path) result(dir)
        character(len=*), intent(in) :: path
        character(len=:), allocatable :: dir
        dir = path(1:index(path, '/', back=.true.))
    end function folder

    !> Component number of 'x' (1) or 'y' (2).
    pure integer function component(word)
        character(len=*), intent(in) :: word
        component = merge(1, 2, word == 'x')
    end function component

    !> 'static analysis, 400 elements, 882 dofs (40 prescribed)'.
    function continuum_describe(self) result(text)
        !> The simulation.
        class(continuum_simulation_t), intent(in) :: self
        !> Summary.
        character(len=:), allocatable :: text
        text = self%settings%analysis//' analysis of a continuum, '//to_str(self%model%mesh%element_count())// &
               ' elements, '//to_str(self%model%mesh%node_count())//' nodes, '//to_str(self%ops%n_free)//' free dofs'
    end function continuum_describe

    !> '': static and modal analyses write no checkpoint.
    function continuum_checkpoint_kind(self) result(kind)
        !> The simulation.
        class(continuum_simulation_t), intent(in) :: self
        !> Kind of run of its checkpoints.
        character(len=:), allocatable :: kind
        kind = ''
    end function continuum_checkpoint_kind

    !> False: static and modal analyses have no time steps.
    pure logical function continuum_has_time_loop(self)
        !> The simulation.
        class(continuum_simulation_t), intent(in) :: self
        continuum_has_time_loop = .false.
    end function continuum_has_time_loop

    !> Error for particle-only keywords and for [initial] (beam dofs) in a continuum deck.
    subroutine continuum_check_deck(self, deck, error)
        !> The simulation.
        class(continuum_simulation_t), intent(in) :: self
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        !> Error naming the first such keyword, if any.
        type(error_t), allocatable, intent(out) :: error
        call check_particle_keywords_unused(deck, error)
        if (allocated(error)) return
        call check_initial_unused(deck, error)
    end subroutine continuum_check_deck

    !> No warning.
    function continuum_deck_warnings(self, deck) result(warnings)
        !> The simulation.
        class(continuum_simulation_t), intent(in) :: self
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        !> None.
        type(string_t), allocatable :: warnings(:)
        allocate (warnings(0))
    end function continuum_deck_warnings

    !> The continuum's part of a memory estimate (a continuum run's, a coupled one's): the
    !> elements of each rectangle mesh, each kind with its own figure (a Gmsh file's are not
    !> known before it is read). A rectangle with more nodes or elements than a mesh can number
    !> is an input error.
    subroutine continuum_size_estimate(self, deck, estimate, error)
        !> The simulation (not yet initialised).
        class(continuum_simulation_t), intent(in) :: self
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        !> The estimate, the elements added.
        type(size_estimate_t), intent(inout) :: estimate
        !> Set on a rectangle too large to number, naming file, line and keyword.
        type(error_t), allocatable, intent(out) :: error
        type(element_slot_t) :: element
        type(model_size_t) :: part
        integer(i8) :: n_nodes, n_elements
        character(len=:), allocatable :: message
        integer :: k
        do k = 1, size(deck%entries)
            associate (e => deck%entries(k))
                if (e%section /= 'continuum' .or. e%keyword /= 'mesh') cycle
                if (e%word('kind') /= 'rectangle') cycle
                ! The schema admits only the names of registered element kinds.
                call new_element(kind_of_name(e%word('element')), element)
                call check_rectangle_size(e%int('nx'), e%int('ny'), element%element, error)
                if (allocated(error)) then
                    message = error%message
                    call make_input_error(error, deck%file, e%line, e%keyword, message)
                    return
                end if
                call rectangle_size(e%int('nx'), e%int('ny'), element%element, n_nodes, n_elements)
                ! the memory model has a figure per kind (driver_model_size): a kind without
                ! one is an internal error, not Q4's figure
                part = model_size_t()
                select case (element%element%name())
                case ('t3')
                    part%t3 = n_elements
                case ('q4')
                    part%q4 = n_elements
                case default
                    call make_internal_error(error, 'check_model_size', 'no memory figure for the element kind '// &
                                             element%element%name()//' (driver_model_size)')
                    return
                end select
                call estimate%add_record(part, k, e)
            end associate
        end do
    end subroutine continuum_size_estimate

    !> See `simulation_t%inputs_text`: the hash of the Gmsh mesh file ('' for a generated mesh).
    function continuum_inputs_text(self) result(text)
        !> The simulation (after `init`).
        class(continuum_simulation_t), intent(in) :: self
        !> The mesh file's hash.
        character(len=:), allocatable :: text
        text = ''
        if (allocated(self%mesh_hash)) text = self%mesh_hash
    end function continuum_inputs_text
end module driver_simulation_continuum
