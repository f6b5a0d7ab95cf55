!> 2D continuum runs: a [continuum] deck (no [beam], no [particles]); static, modal or dynamic.
!>
!> The mesh comes from the rectangle generator or a Gmsh file; the deck's named sets are the
!> mesh's (a Gmsh mesh gets the sets 'all' of its nodes and elements as well). Static: K_ff
!> u_f = f_f - K_fp u_p by CHOLMOD. Modal: band LAPACK (dsbgvx) on the reduced K and M. Dynamic:
!> the integrators of fem_newmark on the continuum as a `dynamic_operator_t`, with checkpoints
!> and restart as the beam's (driver_checkpoint: the integrator's state and the results file's
!> record counts).
module driver_simulation_continuum
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use core_kinds, only: wp, i8
    use core_constants, only: two_pi
    use core_error, only: error_t, make_error, make_input_error
    use core_strings, only: string_t, to_str
    use core_signals, only: caught_signal, signal_name
    use io_deck, only: deck_t, deck_entry_t
    use io_progress, only: progress_t
    use fem_mesh2d, only: mesh2d_t
    use fem_mesh_generator, only: rectangle_mesh
    use fem_gmsh_reader, only: read_gmsh
    use io_paths, only: read_file_text
    use fem_elastic2d, only: elastic2d_t, make_elastic2d
    use fem_continuum_model, only: continuum_model_t
    use fem_continuum_dynamics, only: continuum_dynamics_t, continuum_audit_t
    use fem_dynamic_operator, only: spd_factor_t
    use fem_newmark, only: time_integrator_t, newmark_t, central_difference_t, model_out_of_range
    use driver_config, only: run_config_t, build_run_settings, build_time_functions
    use driver_results, only: results_writer_t
    use io_hdf5_file, only: h5_file_t
    use driver_checkpoint, only: deck_hash, checkpoint_run_t, end_of_step, step_end_t, loop_state_t, checkpoint_create, &
                                 save_integrator, load_integrator, save_results, load_results, &
                                 read_finite_attribute
    use driver_results_continuum, only: continuum_writer_t
    use driver_simulation, only: simulation_t, report_iface
    implicit none
    private
    public :: continuum_simulation_t

    !> A 2D continuum run.
    type, extends(simulation_t) :: continuum_simulation_t
        !> The continuum (mesh, materials, loads, prescribed dofs).
        type(continuum_model_t) :: model
        !> K, M and loads on the free dofs.
        type(continuum_dynamics_t) :: ops
        !> Time integrator (dynamic).
        class(time_integrator_t), allocatable :: integ
        !> Factor of K_ff (static).
        class(spd_factor_t), allocatable :: k_factor
        !> Deck file.
        character(len=:), allocatable :: deck_file
        !> Energy audit of the whole body (prescribed dofs and their reactions included).
        type(continuum_audit_t) :: audit
        !> Hash of the Gmsh mesh file's text ('' for a generated mesh), for the checkpoints.
        character(len=:), allocatable :: mesh_hash
    contains
        !> See `simulation_t%init`.
        procedure :: init => continuum_init
        !> See `simulation_t%describe`.
        procedure :: describe => continuum_describe
        !> See `simulation_t%run`.
        procedure :: run => continuum_run
        !> See `simulation_t%checkpoint_kind`.
        procedure :: checkpoint_kind => continuum_checkpoint_kind
        !> See `simulation_t%inputs_text`: the Gmsh mesh file.
        procedure :: inputs_text => continuum_inputs_text
    end type continuum_simulation_t

contains

    !> Mesh, model, boundary conditions, loads, run settings and integrator from the deck.
    subroutine continuum_init(self, deck, report, error)
        !> The simulation.
        class(continuum_simulation_t), intent(inout) :: self
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        !> Where warnings go.
        procedure(report_iface) :: report
        !> Set on any input error.
        type(error_t), allocatable, intent(out) :: error
        type(mesh2d_t) :: mesh
        type(deck_entry_t) :: e
        type(deck_entry_t), allocatable :: list(:)
        character(len=:), allocatable :: message
        ! Deck ids of the time functions; constant loads set aside while a timed one is added.
        integer, allocatable :: function_ids(:)
        real(wp), allocatable :: constant(:)
        logical :: lumped
        integer :: line, n_free
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
        lumped = deck%get_word('continuum', 'mass') == 'lumped'
        call self%ops%build(self%model, lumped, deck%get_real('continuum', 'rayleigh', 'a0'), &
                            deck%get_real('continuum', 'rayleigh', 'a1'), error)
        if (allocated(error)) call fail_at(error, deck%line('continuum', 'mesh'), 'mesh')
        if (allocated(error)) return
        call build_run_settings(deck, self%ops%n_free, lumped, 'continuum', self%settings, error)
        if (allocated(error)) return
        select case (self%settings%analysis)
        case ('static')
            if (self%model%stops_rigid_motions()) call self%ops%factor_combination(0.0_wp, 1.0_wp, self%k_factor, error)
            if (allocated(error) .or. .not. self%model%stops_rigid_motions()) then
                line = deck%line('continuum', 'fix')
                if (line == 0) line = deck%line('continuum', 'mesh')
                call make_input_error(error, deck%file, line, 'fix', 'the supports (fix, displacement) do not '// &
                                      'stop every rigid motion (two translations and the rotation): the stiffness '// &
                                      'on the free dofs is singular')
                return
            end if
        case ('modal', 'dynamic')
            call check_density(error)
            if (allocated(error)) return
            if (self%settings%analysis == 'dynamic') call make_integrator(error)
        end select

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
            integer :: i
            if (.not. deck%has('continuum', 'mesh')) then
                call make_input_error(error, deck%file, first_line(), 'mesh', '[continuum] needs a mesh: '// &
                                      'mesh = rectangle x0 y0 lx ly nx ny q4|t3, or mesh = file <name>.msh')
                return
            end if
            e = deck%record('continuum', 'mesh', 1)
            if (e%word('kind') == 'rectangle') then
                call rectangle_mesh(e%real('x0'), e%real('x0') + e%real('lx'), e%real('y0'), e%real('y0') + e%real('ly'), &
                                    e%int('nx'), e%int('ny'), e%word('element') == 't3', mesh, error)
            else
                path = e%word('path')
                if (path(1:1) /= '/') path = folder(deck%file)//path
                call read_gmsh(path, mesh, error)
                if (.not. allocated(error)) call read_file_text(path, text, error)
                if (.not. allocated(error)) self%mesh_hash = deck_hash(text)
                if (.not. allocated(error)) then
                    if (.not. any([(mesh%element_sets(i)%name == 'all', i=1, size(mesh%element_sets))])) &
                        call mesh%add_element_set('all', [(i, i=1, mesh%element_count())])
                    if (.not. any([(mesh%node_sets(i)%name == 'all', i=1, size(mesh%node_sets))])) &
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
                                             'the stiffness or mass of element '//to_str(i)//' overflows or vanishes '// &
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
                                          e%word('node_set')//', component '//merge('x', 'y', comp == 1)// &
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
                do j = 1, size(ids)
                    call self%model%add_nodal_load(ids(j), component(e%word('component')), e%real('value'))
                end do
                call end_load(func)
            end do
            list = deck%records('continuum', 'traction')
            do i = 1, size(list)
                e = list(i)
                call start_load('traction', func, error)
                if (allocated(error)) return
                if (e%word('profile') == 'parabolic') then
                    call self%model%add_traction_parabolic(e%word('edge_set'), [e%real('tx'), e%real('ty')], error)
                else
                    call self%model%add_traction(e%word('edge_set'), [e%real('tx'), e%real('ty')], error)
                end if
                if (allocated(error)) call fail_at(error, e%line, 'traction')
                if (allocated(error)) return
                call end_load(func)
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

        !> After adding the load of record e: a timed load moves to its function's column.
        subroutine end_load(func)
            integer, intent(in) :: func
            if (func == 0) return
            self%model%timed_load(:, func) = self%model%timed_load(:, func) + self%model%load
            self%model%load = constant
        end subroutine end_load

        !> Modes and dynamics need a positive-definite mass: every density > 0.
        subroutine check_density(error)
            type(error_t), allocatable, intent(out) :: error
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

        !> Newmark or central difference from rest with the initial velocity field.
        subroutine make_integrator(error)
            type(error_t), allocatable, intent(out) :: error
            real(wp), allocatable :: u0(:), v0(:), v_all(:)
            integer, allocatable :: eq(:)
            real(wp) :: vx, vy, omega, xc, yc
            integer :: a, n, c
            ! The rotation about (xc, yc) is optional (omega, xc and yc together, the schema checks):
            ! absent, it reads as 0.
            e = deck%record('continuum', 'initial_velocity', 1)
            vx = deck%get_real('continuum', 'initial_velocity', 'vx')
            vy = deck%get_real('continuum', 'initial_velocity', 'vy')
            omega = e%real('omega')
            xc = e%real('xc')
            yc = e%real('yc')
            allocate (v_all(self%model%dof_count()))
            do a = 1, self%model%mesh%node_count()
                v_all(2*a - 1) = vx - omega*(self%model%mesh%x(2, a) - yc)
                v_all(2*a) = vy + omega*(self%model%mesh%x(1, a) - xc)
            end do
            call self%model%equations(eq, n)
            allocate (u0(n), v0(n))
            u0 = 0.0_wp
            do c = 1, size(eq)
                if (eq(c) > 0) v0(eq(c)) = v_all(c)
            end do
            ! A speed whose kinetic energy overflows would stop the run at its initial state,
            ! on an energy that is not finite, blaming loads or moduli.
            if (.not. ieee_is_finite(self%ops%kinetic_energy(v0))) then
                call make_input_error(error, deck%file, e%line, 'initial_velocity', 'the kinetic energy '// &
                                      '1/2 v.M v of this initial velocity is beyond the range of double precision '// &
                                      '(largest nodal speed '//to_str(maxval(abs(v_all)))//' m/s): check vx, vy '// &
                                      'and omega, and the densities of [continuum] material')
                return
            end if
            select case (self%settings%scheme)
            case ('central_difference')
                allocate (central_difference_t :: self%integ)
            case default
                allocate (newmark_t :: self%integ)
                select type (integ => self%integ)
                type is (newmark_t)
                    integ%beta = self%settings%beta
                    integ%gamma = self%settings%gamma
                end select
            end select
            call self%integ%init(self%ops, self%settings%h, 0.0_wp, u0, v0, error)
            if (.not. allocated(error)) return
            if (index(error%message, model_out_of_range) == 1) then
                ! no time step resolves the model: its materials
                call fail_at(error, deck%line('continuum', 'material'), 'material')
            else
                call fail_at(error, deck%line('time', 'step'), 'step')
            end if
        end subroutine make_integrator
    end subroutine continuum_init

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

    !> Static solve, modes or time integration; results into `out` (driver_run adds the XDMF file).
    subroutine continuum_run(self, out, quiet, report, ck, error)
        !> The simulation.
        class(continuum_simulation_t), intent(inout) :: self
        !> The results file.
        type(results_writer_t), intent(inout) :: out
        !> No progress lines.
        logical, intent(in) :: quiet
        !> Where progress and summary lines go.
        procedure(report_iface) :: report
        !> Checkpoints of a dynamic run (and the one to restart from).
        type(checkpoint_run_t), intent(inout) :: ck
        !> Set on a run or write failure.
        type(error_t), allocatable, intent(out) :: error
        type(continuum_writer_t) :: writer
        ! Steps done, and at the start of the loop (a checkpoint's at a restart).
        integer(i8) :: k, k0
        ! At a restart the file has the mesh and the series already (run_dynamic's restore).
        if (.not. ck%restart) call writer%begin(out%file, self%model%mesh, self%settings%analysis, error)
        if (allocated(error)) return
        select case (self%settings%analysis)
        case ('static')
            call run_static(error)
        case ('modal')
            call run_modal(error)
        case ('dynamic')
            call run_dynamic(error)
        end select

    contains

        !> What makes a step's state blow up: the stability limit only for a conditionally
        !> stable scheme (central differences, or Newmark with 2 beta < gamma).
        function likely_cause() result(cause)
            character(len=:), allocatable :: cause
            if (self%settings%scheme == 'central_difference' .or. &
                2*self%settings%beta < self%settings%gamma) then
                cause = 'a time step above the stability limit of the scheme, or loads far too large'
            else
                cause = 'loads, moduli or densities far out of range (this Newmark scheme is '// &
                        'unconditionally stable: the time step is not the cause)'
            end if
        end function likely_cause

        !> K_ff u_f = f_f - K_fp u_p.
        subroutine run_static(error)
            type(error_t), allocatable, intent(out) :: error
            real(wp), allocatable :: uf(:), u(:), stress(:, :)
            character(len=160) :: buf
            real(wp) :: energy
            ! Loads at t = 0 (their time functions' values there, as for the beam).
            allocate (uf(self%ops%n_free))
            call self%ops%static_force(0.0_wp, uf)
            call self%k_factor%solve(uf, error)
            if (allocated(error)) return
            u = self%model%expand(uf)
            call self%model%centre_stresses(u, stress, error)
            if (allocated(error)) return
            if (.not. (all(ieee_is_finite(u)) .and. all(ieee_is_finite(stress)))) then
                call make_error(error, 'static solution of the continuum: a displacement or a stress is not '// &
                                'finite; likely cause: loads or moduli far too large or too small')
                return
            end if
            energy = self%ops%total_strain_energy(u)
            if (.not. ieee_is_finite(energy)) then
                call make_error(error, 'static solution of the continuum: the strain energy is not finite; likely '// &
                                'cause: loads or moduli far too large or too small')
                return
            end if
            call writer%write_static(out%file, reshape(u, [2, size(u)/2]), stress, energy, error)
            if (allocated(error)) return
            write (buf, '(a,es13.5e3,a,es13.5e3,a)') 'static solution: max |displacement| = ', maxval(abs(u)), &
                ' m, strain energy = ', energy, ' J'
            call report(trim(buf))
        end subroutine run_static

        !> Lowest modes.
        subroutine run_modal(error)
            type(error_t), allocatable, intent(out) :: error
            real(wp), allocatable :: omega(:), shapes(:, :), full(:, :, :), u(:)
            character(len=120) :: buf
            integer :: k
            call self%ops%solve_modes(self%settings%n_modes, omega, shapes, error)
            if (allocated(error)) return
            allocate (full(2, self%model%mesh%node_count(), size(omega)))
            do k = 1, size(omega)
                ! Mode shapes vanish on the prescribed dofs.
                u = self%model%expand(shapes(:, k)) - self%model%prescribed_at(0.0_wp, 0)
                full(:, :, k) = reshape(u, [2, self%model%mesh%node_count()])
                write (buf, '(a,i3,a,es15.7e3,a,es15.7e3,a)') 'mode ', k, ': omega = ', omega(k), &
                    ' rad/s, f = ', omega(k)/two_pi, ' Hz'
                call report(trim(buf))
            end do
            call writer%write_modal(out%file, omega, full, error)
        end subroutine run_modal

        !> Time steps with outputs every [output] interval, checkpoints as `ck` says (from a
        !> checkpoint's state at a restart).
        subroutine run_dynamic(error)
            type(error_t), allocatable, intent(out) :: error
            type(progress_t) :: progress
            integer(i8) :: n_steps
            type(step_end_t) :: act
            character(len=200) :: buf
            n_steps = self%settings%n_steps
            call progress%start(n_steps, self%settings%t_end, self%settings%progress_seconds)
            k0 = 0
            if (ck%restart) then
                call restore(error)
            else
                call self%audit%start(self%ops, self%model, self%integ)
                call store(error)
            end if
            if (allocated(error)) return
            call ck%schedule%start()
            do k = k0 + 1, n_steps
                call self%integ%step(self%ops, error)
                if (allocated(error)) return
                call self%audit%advance(self%ops, self%model, self%integ)
                ! State and energy accounts (a checkpoint may follow: it must hold finite values).
                if (.not. (all(ieee_is_finite(self%integ%u)) .and. all(ieee_is_finite(self%integ%v)) .and. &
                           all(ieee_is_finite([self%integ%kinetic, self%integ%strain, self%integ%external_work, &
                                               self%integ%damping_dissipation, self%audit%balance()])))) then
                    write (buf, '(a,i0,a,es13.5e3,a)') 'continuum: the state is not finite after step ', k, &
                        ' (t = ', self%integ%t, ' s); likely cause:'
                    call make_error(error, trim(buf)//' '//likely_cause())
                    return
                end if
                act = end_of_step(k, n_steps, self%settings%output_interval, ck%schedule)
                if (act%store_first) call store(error)
                if (act%checkpoint .and. .not. allocated(error)) call checkpoint(error)
                if (act%store_last .and. .not. allocated(error)) call store(error)
                if (allocated(error)) return
                if (act%stop) then
                    ! Stop request: the step just done is the last output.
                    call out%stop_at(signal_name(caught_signal()), k, self%integ%t)
                    n_steps = k
                    exit
                end if
                if (.not. quiet) then
                    if (progress%due()) call report(progress%line(k, self%integ%t))
                end if
            end do
            write (buf, '(a,i0,a,es13.5e3,a,es11.3e3,a)') 'dynamic run: ', n_steps, ' steps to t = ', &
                self%integ%t, ' s; energy balance residual ', self%audit%balance(), ' J'
            call report(trim(buf))
            call report(progress%summary_line(n_steps, stopped=out%stopped()))
            call out%write_summary(int(n_steps), progress%elapsed(), error)
        end subroutine run_dynamic

        !> Restart: integrator state, results file and writer from the checkpoint `ck%source`.
        subroutine restore(error)
            type(error_t), allocatable, intent(out) :: error
            type(error_t), allocatable :: ignored
            real(wp), allocatable :: totals(:)
            call load_integrator(ck%source, '/fe', self%integ, ck%start%step, error)
            if (.not. allocated(error)) call read_finite_attribute(ck%source, '/fe', 'continuum_audit', totals, 4, error)
            if (.not. allocated(error)) call self%audit%resume(self%ops, self%model, self%integ, totals)
            if (.not. allocated(error)) call load_results(ck%source, out, error)
            call ck%source%close(ignored)
            if (allocated(error)) return
            call writer%resume(out%file, self%model%mesh, error)
            k0 = ck%start%step
        end subroutine restore

        !> Write a checkpoint after step k.
        subroutine checkpoint(error)
            type(error_t), allocatable, intent(out) :: error
            type(h5_file_t) :: f
            call out%flush(error)
            if (allocated(error)) return
            call checkpoint_create(f, ck%path, ck%deck_text, self%checkpoint_kind(), &
                                   loop_state_t(k, 0, .false., .false.), self%integ%t, out%run_id, error)
            if (.not. allocated(error)) call save_integrator(f, '/fe', self%integ, error)
            if (.not. allocated(error)) call f%write_attribute('/fe', 'continuum_audit', self%audit%totals(), error)
            if (.not. allocated(error)) call save_results(f, out, error)
            call ck%finish(f, k, self%integ%t, error)
        end subroutine checkpoint

        !> Store the current state and energies.
        subroutine store(error)
            type(error_t), allocatable, intent(out) :: error
            real(wp), allocatable :: u(:), v(:), stress(:, :)
            real(wp) :: energies(5)
            character(len=200) :: buf
            integer :: n
            u = self%model%expand(self%integ%u, self%integ%t)
            v = self%model%expand(self%integ%v, self%integ%t, 1)
            n = self%model%mesh%node_count()
            call self%model%centre_stresses(u, stress, error)
            if (allocated(error)) return
            associate (g => self%integ, au => self%audit)
                energies = [au%kinetic, au%strain, au%load_work, au%damping, au%balance()]
                if (.not. (all(ieee_is_finite(stress)) .and. all(ieee_is_finite(energies)))) then
                    write (buf, '(a,es13.5e3,a)') 'continuum: a stress or an energy is not finite at t = ', g%t, &
                        ' s; likely cause: loads or moduli far too large or too small'
                    call make_error(error, trim(buf))
                    return
                end if
                call writer%store(out%file, g%t, reshape(u, [2, n]), reshape(v, [2, n]), stress, error)
                if (allocated(error)) return
                call writer%store_energy(out%file, g%t, energies(1), energies(2), energies(3), energies(4), &
                                         energies(5), error, au%reaction_work, au%reaction_resultant)
            end associate
            if (allocated(error)) return
            call out%flush(error)
        end subroutine store
    end subroutine continuum_run

    !> 'continuum' for a dynamic analysis (static and modal ones write no checkpoint).
    function continuum_checkpoint_kind(self) result(kind)
        !> The simulation.
        class(continuum_simulation_t), intent(in) :: self
        !> Kind of run of its checkpoints.
        character(len=:), allocatable :: kind
        kind = ''
        if (self%settings%analysis == 'dynamic') kind = 'continuum'
    end function continuum_checkpoint_kind
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
