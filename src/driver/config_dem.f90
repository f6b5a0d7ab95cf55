!> From a validated deck to a discrete-element system (`dem_config_t`): materials, disks from
!> the `disk` records and the generators, gravity, DOF conditions, loads and initial
!> velocities on selections of disks, walls, contact laws, time-stepping and solver settings.
!> The deck reader has checked each line on its own; here come the checks across lines: ids
!> of materials and functions, selections against the number of disks, conflicting
!> conditions on a DOF, duplicate laws, walls of zero length or repeated, disks that overlap each other or
!> a wall at t = 0. Each error names the deck file, the line and the keyword concerned.
!>
!> Disks are numbered 1..N in the order the deck creates them (file order of `disk`, `row`,
!> `square_lattice`, `hex_lattice` and `deposit`, each generator in its own order); materials
!> and walls are numbered in file order; a time function is referred to by its [functions]
!> id and stored by its position among the `function` records (as driver_config does).
!> The model types of the DEM library (particles_t, walls_t, materials_t) are plain data, so
!> they are filled directly: `dem_config_t%system` is ready for `mj_init`.
module driver_config_dem
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use core_kinds, only: wp, i8
    use core_constants, only: deg_to_rad, pi
    use core_error, only: error_t, make_input_error, make_internal_error
    use core_strings, only: string_t, to_str, sci_to_str, num => sci_text
    use core_timefunc, only: time_function_slot_t
    use io_deck, only: deck_t, deck_entry_t
    use io_deck_schema, only: parse_selection
    use io_memory, only: available_memory
    use core_sort, only: sort_index
    use dem_activation, only: activation_siconos_t, activation_predicted_t
    use dem_particles, only: particles_add_disks, particles_fix, particles_impose_velocity, &
                             particles_add_load, dof_x, dof_y, dof_rot
    use dem_generators, only: generate_row, generate_square_lattice, generate_hex_lattice, &
                              generate_random_deposit
    use dem_walls, only: walls_add
    use dem_materials, only: materials_init, materials_set_pair, materials_set_bond, bond_e_default
    use dem_contacts, only: contact_set_t
    use dem_detection, only: detector_t, detect_contacts, coordinate_limit
    use dem_moreau_jean, only: dem_system_t, mj_bonds_at_start
    use dem_nlgs_criterion, only: lmgc90_criterion_t, siconos_criterion_t
    use dem_solve_method, only: sweeps_method_t
    use dem_bonded_block, only: bonded_block_method_t
    use dem_coarse, only: coarse_correction_t
    use dem_cold_start, only: hydrostatic_start_t
    use driver_config, only: run_config_t
    use driver_config_beam, only: repeated_dof
    implicit none
    private
    public :: dem_config_t, build_dem_config
    public :: default_alert_ratio, overlap_tolerance, default_gap_ratio

    !> Default alert distance as a fraction of the mean disk radius.
    real(wp), parameter :: default_alert_ratio = 0.25_wp
    !> Overlaps at t = 0 larger than this fraction of the pair's mean radius are errors.
    real(wp), parameter :: overlap_tolerance = 1.0e-6_wp
    !> Largest number of disks of a deck (keeps 3 N DOF indices in default integers).
    integer(i8), parameter :: max_disks = 500000000_i8
    !> Default gap_ratio of the `deposit` generator.
    real(wp), parameter :: default_gap_ratio = 0.1_wp
    !> Condition kinds on a DOF while building (free, fixed, imposed velocity).
    integer, parameter :: free = 0, fixed = 1, imposed = 2
    !> DOF words of the deck, in DOF order.
    character(len=3), parameter :: dof_names(3) = ['x  ', 'y  ', 'rot']

    !> A discrete-element model ready to run, with what is needed to report and store it.
    type :: dem_config_t
        !> Disks, walls, materials, scheme and solver settings (mj_init not called yet).
        type(dem_system_t) :: system
        !> Deck id of each material (position = material index of the system).
        integer, allocatable :: material_id(:)
        !> Deck line that created each disk.
        integer, allocatable :: disk_line(:)
        !> Deck line of each wall.
        integer, allocatable :: wall_line(:)
        !> Store the contact network with every stored state.
        logical :: store_contacts = .true.
        !> The alert distance is the default one (not given in the deck).
        logical :: default_alert = .true.
        !> Step whose local contact problem is written in FCLIB's format (0: none).
        integer :: fclib_step = 0
        !> Warnings about the model, 'warning: file:line: ...' (printed by the simulation).
        type(string_t), allocatable :: warnings(:)
    end type dem_config_t

contains

    !> Build the discrete-element system of a deck with [particles].
    subroutine build_dem_config(deck, run, functions, cfg, error)
        !> Deck read by io_deck::read_deck with the MULTICOR schema.
        type(deck_t), intent(in) :: deck
        !> Run settings built by driver_config::build_config (time step).
        type(run_config_t), intent(in) :: run
        !> Time functions of the deck, in the order of the `function` records (as built by
        !> driver_config::build_config).
        type(time_function_slot_t), intent(in) :: functions(:)
        !> The model.
        type(dem_config_t), intent(out) :: cfg
        !> Error naming file, line and keyword, if any.
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: function_ids(:)
        type(deck_entry_t), allocatable :: list(:)
        real(wp), allocatable :: density(:)
        integer :: i
        allocate (list, source=deck%records('functions', 'function'))
        allocate (function_ids(size(list)))
        do i = 1, size(list)
            function_ids(i) = list(i)%int('id')
        end do
        call build_materials(deck, cfg, density, error)
        if (allocated(error)) return
        call build_disks(deck, density, cfg, error)
        if (allocated(error)) return
        call check_disk_coordinates(deck, cfg, error)
        if (allocated(error)) return
        cfg%system%particles%functions = functions
        cfg%system%walls%functions = functions
        cfg%system%particles%gravity = [deck%get_real('particles', 'gravity', 'gx'), &
                                        deck%get_real('particles', 'gravity', 'gy')]
        call build_walls(deck, function_ids, cfg, error)
        if (allocated(error)) return
        call build_conditions(deck, function_ids, cfg, error)
        if (allocated(error)) return
        call build_laws(deck, cfg, error)
        if (allocated(error)) return
        call build_settings(deck, run, cfg, error)
        if (allocated(error)) return
        call check_overlaps(deck, cfg, error)
        if (allocated(error)) return
        call check_alert_reach(deck, cfg, available_memory(), error)
        if (allocated(error)) return
        call warn_bonds_without_pairs(deck, cfg)
    end subroutine build_dem_config

    !> Warn about each `[contacts] bond` record that bonds no pair at t = 0 (the bonds of the
    !> first step, mj_bonds_at_start): no body of one of its materials touches one of the
    !> other, and bonds form only then, so the record has no effect. A cohesive law alone
    !> is not warned about: its contacts that form later follow the law.
    subroutine warn_bonds_without_pairs(deck, cfg)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> The model (disks, walls, materials and settings built); warnings appended.
        type(dem_config_t), intent(inout) :: cfg
        type(deck_entry_t), allocatable :: list(:)
        integer, allocatable :: bonds(:, :)
        character(len=:), allocatable :: pairs
        integer :: i, a, b
        allocate (list, source=deck%records('contacts', 'bond'))
        if (size(list) == 0) return
        bonds = mj_bonds_at_start(cfg%system)
        do i = 1, size(list)
            associate (e => list(i))
                ! (build_bonds checked that both materials are defined)
                a = findloc(cfg%material_id, e%int('material1'), dim=1)
                b = findloc(cfg%material_id, e%int('material2'), dim=1)
                if (bonds(a, b) > 0) cycle
                if (a == b) then
                    pairs = 'no two bodies of material '//e%word('material1')//' touch'
                else
                    pairs = 'no body of material '//e%word('material1')//' touches one of material '// &
                            e%word('material2')
                end if
                cfg%warnings = [cfg%warnings, string_t('warning: '//deck%file//':'//to_str(e%line)// &
                                                       ': [contacts] bond between materials '//e%word('material1')// &
                                                       ' and '//e%word('material2')//' makes no bond: '//pairs// &
                                                       ' at t = 0 (a gap of at most '//to_str(cfg%system%scheme%bond_ratio)// &
                                                       ' times the mean radius of the pair), and bonds form only '// &
                                                       'then; place the disks in contact at t = 0 (e.g. a lattice), '// &
                                                       'or remove the record')]
            end associate
        end do
    end subroutine warn_bonds_without_pairs

    !> Error when the alert distance makes so many disk pairs contact candidates that their
    !> contact list would not fit in the available memory (nothing checked when that is
    !> unknown, available < 0). The pairs within reach = 2 r_max + alert are estimated on a
    !> grid of cells of side `reach` (sorted cell keys, no dense grid): a disk of a cell
    !> holding c disks has about pi c other disks within reach (the density c/reach^2 over
    !> the disk of radius reach), so a cell adds about pi c^2/2 pairs; capped at n(n - 1)/2.
    !> Each candidate costs about bytes_per_candidate. A dense packing gives about 2.5 pairs
    !> per disk, 10^5 disks about 0.1 GiB: only alert distances of many radii come near the
    !> limit.
    subroutine check_alert_reach(deck, cfg, available, error)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> The model (disks, alert distance).
        type(dem_config_t), intent(in) :: cfg
        !> Available memory [bytes] (-1: unknown).
        integer(i8), intent(in) :: available
        !> Error naming [contacts] alert, if any.
        type(error_t), allocatable, intent(out) :: error
        !> Contact set arrays (about 45 reals and integers per contact, the previous list,
        !> the detection's candidate buffers): 500 bytes per pair, rounded up.
        integer(i8), parameter :: bytes_per_candidate = 500
        integer(i8), allocatable :: key(:)
        integer, allocatable :: order(:)
        character(len=:), allocatable :: advice
        real(wp) :: reach, x0, y0, pairs
        integer :: i, run_start
        if (available < 0) return
        associate (p => cfg%system%particles)
            if (p%n < 2) return
            reach = 2.0_wp*maxval(p%radius(1:p%n)) + cfg%system%scheme%alert
            x0 = minval(p%x(1:p%n))
            y0 = minval(p%y(1:p%n))
            allocate (key(p%n))
            do i = 1, p%n
                key(i) = ishft(int(min((p%x(i) - x0)/reach, 2.0e9_wp), i8), 32) + &
                         int(min((p%y(i) - y0)/reach, 2.0e9_wp), i8)
            end do
            order = sort_index(key)
            pairs = 0.0_wp
            run_start = 1
            do i = 2, p%n + 1
                if (i <= p%n) then
                    if (key(order(i)) == key(order(run_start))) cycle
                end if
                pairs = pairs + 0.5_wp*pi*real(i - run_start, wp)**2
                run_start = i
            end do
            pairs = min(pairs, 0.5_wp*real(p%n, wp)*real(p%n - 1, wp))
            if (pairs*real(bytes_per_candidate, wp) <= real(available, wp)) return
            ! an alert already below the largest radius is not the cause: the disks are too many
            advice = 'use an alert distance of a fraction of the radius'
            if (cfg%system%scheme%alert <= maxval(p%radius(1:p%n))) &
                advice = 'the alert is already below the largest radius ('// &
                         length_text(maxval(p%radius(1:p%n)))//' m): the deck has too many disks for '// &
                         'this machine ('//to_str(p%n)//')'
            call make_input_error(error, deck%file, deck%line('contacts', 'alert'), 'alert', &
                                  '[contacts] alert = '//length_text(cfg%system%scheme%alert)// &
                                  ' m makes up to about '//length_text(pairs)//' disk pairs contact '// &
                                  'candidates (disks within 2 r_max + alert of each other), about '// &
                                  length_text(pairs*real(bytes_per_candidate, wp)/1024.0_wp**3)// &
                                  ' GiB, more than the memory available: '//advice)
        end associate
    end subroutine check_alert_reach

    !> Materials: unique ids, densities; the material table of the contact laws.
    subroutine build_materials(deck, cfg, density, error)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> The model (material_id filled, material table initialised).
        type(dem_config_t), intent(inout) :: cfg
        !> Density of each material [kg/m^3].
        real(wp), allocatable, intent(out) :: density(:)
        !> Error, if any.
        type(error_t), allocatable, intent(out) :: error
        type(deck_entry_t), allocatable :: list(:)
        integer :: i, j
        allocate (list, source=deck%records('particles', 'material'))
        allocate (cfg%material_id(size(list)), density(size(list)))
        do i = 1, size(list)
            cfg%material_id(i) = list(i)%int('id')
            density(i) = list(i)%real('density')
            j = findloc(cfg%material_id(:i - 1), cfg%material_id(i), dim=1)
            if (j > 0) then
                call make_input_error(error, deck%file, list(i)%line, 'material', &
                                      'duplicate material id '//list(i)%word('id')//': already defined on line '// &
                                      to_str(list(j)%line))
                return
            end if
        end do
        if (size(list) > 0) call materials_init(cfg%system%materials, size(list), error)
    end subroutine build_materials

    !> Disks from `disk` records and generators, in file order.
    subroutine build_disks(deck, density, cfg, error)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> Density of each material [kg/m^3].
        real(wp), intent(in) :: density(:)
        !> The model (disks and disk_line filled).
        type(dem_config_t), intent(inout) :: cfg
        !> Error, if any.
        type(error_t), allocatable, intent(out) :: error
        real(wp), allocatable :: x(:), y(:), r(:), gx(:), gy(:), gr(:)
        integer, allocatable :: mat(:), line(:)
        integer(i8) :: total
        integer :: i, n, k, stat, first_line
        ! Sizes first, so that arrays are allocated once.
        total = 0
        first_line = 0
        do i = 1, size(deck%entries)
            associate (e => deck%entries(i))
                if (e%section /= 'particles') cycle
                if (first_line == 0) first_line = e%line
                select case (e%keyword)
                case ('disk')
                    total = total + 1
                case ('row', 'deposit')
                    total = total + e%int('n')
                case ('square_lattice', 'hex_lattice')
                    total = total + int(e%int('nx'), i8)*int(e%int('ny'), i8)
                end select
            end associate
        end do
        if (total == 0) then
            call make_input_error(error, deck%file, first_line, '', 'no disk: add [particles] '// &
                                  'disk records or generators (row, square_lattice, hex_lattice, deposit)')
            return
        end if
        stat = 1
        if (total < max_disks) allocate (x(total), y(total), r(total), mat(total), line(total), &
                                         stat=stat)
        if (stat /= 0) then
            call make_input_error(error, deck%file, 0, '', 'the model is too large: cannot '// &
                                  'hold '//to_str(real(total, wp))//' disks in memory')
            return
        end if
        n = 0
        do i = 1, size(deck%entries)
            associate (e => deck%entries(i))
                if (e%section /= 'particles') cycle
                select case (e%keyword)
                case ('disk', 'row', 'square_lattice', 'hex_lattice', 'deposit')
                case default
                    cycle
                end select
                call generate(e, gx, gy, gr, error)
                if (allocated(error)) return
                k = material_index(e%int('material'))
                if (k == 0) then
                    call make_input_error(error, deck%file, e%line, e%keyword, 'material '// &
                                          e%word('material')//' is not defined (no [particles] '// &
                                          'material record with this id)')
                    return
                end if
                x(n + 1:n + size(gx)) = gx
                y(n + 1:n + size(gx)) = gy
                r(n + 1:n + size(gx)) = gr
                mat(n + 1:n + size(gx)) = k
                line(n + 1:n + size(gx)) = e%line
                n = n + size(gx)
            end associate
        end do
        call particles_add_disks(cfg%system%particles, x(:n), y(:n), r(:n), density(mat(:n)), &
                                 error)
        if (allocated(error)) return
        ! Masses and inertias must be normal numbers: an inertia that underflows to zero (radius
        ! 1e-100 m) gives a NaN rotation at the first step, a mass that overflows (radius 1e150
        ! m) a non-finite energy; both with no force at all.
        do k = 1, n
            associate (m => cfg%system%particles%mass(k), inertia => cfg%system%particles%inertia(k))
                if (m >= tiny(m) .and. m <= huge(m) .and. inertia >= tiny(m) .and. inertia <= huge(m)) cycle
                call make_input_error(error, deck%file, line(k), '', 'disk '//to_str(k)//' (radius '// &
                                      to_str(r(k))//' m, density '//to_str(density(mat(k)))//' kg/m3): its '// &
                                      'mass pi density radius^2 = '//to_str(m)//' kg/m or its moment of '// &
                                      'inertia mass radius^2 / 2 = '//to_str(inertia)//' kg m is beyond the '// &
                                      'range of double precision (2.2e-308 to 1.8e308): check the radius '// &
                                      '(in m) and the density (in kg/m3)')
                return
            end associate
        end do
        cfg%system%particles%mat(1:n) = mat(:n)
        cfg%disk_line = line(:n)

    contains

        !> Position of the material with deck id `id` (0 if none).
        integer function material_index(id)
            integer, intent(in) :: id
            material_index = findloc(cfg%material_id, id, dim=1)
        end function material_index

        !> Centres and radii of one record.
        subroutine generate(e, gx, gy, gr, error)
            type(deck_entry_t), intent(in) :: e
            real(wp), allocatable, intent(out) :: gx(:), gy(:), gr(:)
            type(error_t), allocatable, intent(out) :: error
            real(wp) :: gap_ratio, pitch
            character(len=:), allocatable :: message
            select case (e%keyword)
            case ('disk')
                gx = [e%real('x')]
                gy = [e%real('y')]
                gr = [e%real('radius')]
            case ('row')
                call generate_row(e%int('n'), e%real('x0'), e%real('y0'), e%real('radius'), e%real('gap'), &
                                  e%real('angle_deg')*deg_to_rad, gx, gy, gr, error)
            case ('square_lattice')
                call generate_square_lattice(e%int('nx'), e%int('ny'), e%real('x0'), e%real('y0'), &
                                             e%real('radius'), e%real('gap'), gx, gy, gr, error)
            case ('hex_lattice')
                call generate_hex_lattice(e%int('nx'), e%int('ny'), e%real('x0'), e%real('y0'), &
                                          e%real('radius'), e%real('gap'), gx, gy, gr, error)
            case ('deposit')
                gap_ratio = default_gap_ratio
                if (e%has('gap_ratio')) gap_ratio = e%real('gap_ratio')
                if (e%real('rmax') < e%real('rmin')) then
                    call make_input_error(error, deck%file, e%line, e%keyword, 'rmax '// &
                                          e%word('rmax')//' is smaller than rmin '//e%word('rmin'))
                    return
                end if
                pitch = 2.0_wp*e%real('rmax')*(1.0_wp + gap_ratio)
                if (e%real('xmax') - e%real('xmin') < pitch) then
                    call make_input_error(error, deck%file, e%line, e%keyword, 'the box from '// &
                                          'xmin = '//e%word('xmin')//' to xmax = '//e%word('xmax')//' is narrower than one '// &
                                          'site 2 rmax (1 + gap_ratio) = '//to_str(pitch)//' m')
                    return
                end if
                call generate_random_deposit(e%int('n'), e%real('xmin'), e%real('xmax'), e%real('ymin'), &
                                             e%real('rmin'), e%real('rmax'), gap_ratio, e%int('seed'), gx, gy, gr, error)
            end select
            if (allocated(error)) then
                message = error%message
                call make_input_error(error, deck%file, e%line, e%keyword, message)
            end if
        end subroutine generate
    end subroutine build_disks

    !> Disk centres must lie in the box the contact detection can represent
    !> (dem_detection::coordinate_limit); checked before anything else uses them (the walls'
    !> lengths are compared with the size of the model).
    subroutine check_disk_coordinates(deck, cfg, error)
        !> The deck (for messages).
        type(deck_t), intent(in) :: deck
        !> The model (disks and disk_line filled).
        type(dem_config_t), intent(in) :: cfg
        !> Set when a disk lies beyond the box.
        type(error_t), allocatable, intent(out) :: error
        real(wp) :: limit
        integer :: k
        associate (p => cfg%system%particles)
            if (p%n == 0) return
            limit = coordinate_limit(minval(p%radius(1:p%n)))
            do k = 1, p%n
                if (max(abs(p%x(k)), abs(p%y(k))) <= limit) cycle
                call make_input_error(error, deck%file, cfg%disk_line(k), '', 'disk '// &
                                      to_str(k)//' at ('//num(p%x(k))//', '//num(p%y(k))// &
                                      ') m lies beyond the box the run can represent: |x|, |y| <= '// &
                                      num(limit)//' m (4.5e9 times the smallest radius, at most '// &
                                      '1e100 m; coordinates are then known to 1e-6 of the radius)')
                return
            end do
        end associate
    end subroutine check_disk_coordinates

    !> The walls, each of 4, 5, 7 or 8 values, with a known material and function, inside the
    !> box the contact detection can represent, and of non-zero length.
    subroutine build_walls(deck, function_ids, cfg, error)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> Deck id of each time function.
        integer, intent(in) :: function_ids(:)
        !> The model (walls and wall_line filled).
        type(dem_config_t), intent(inout) :: cfg
        !> Error, if any.
        type(error_t), allocatable, intent(out) :: error
        type(deck_entry_t), allocatable :: list(:)
        real(wp) :: vx, vy, length, size_model, limit
        character(len=:), allocatable :: message
        integer :: i, mat, func
        logical :: has_vx, has_vy
        allocate (list, source=deck%records('walls', 'wall'))
        allocate (cfg%wall_line(size(list)))
        size_model = model_size(cfg, list)
        limit = coordinate_limit(minval(cfg%system%particles%radius(1:cfg%system%particles%n)))
        do i = 1, size(list)
            associate (e => list(i))
                cfg%wall_line(i) = e%line
                has_vx = e%has('vx')
                has_vy = e%has('vy')
                if (has_vx .and. .not. has_vy) then
                    call make_input_error(error, deck%file, e%line, 'wall', 'the wall velocity '// &
                                          "needs both vx and vy: expected 'x1 y1 x2 y2 [material] [vx vy "// &
                                          "[function]]', got 6 values")
                    return
                end if
                mat = 1
                if (e%has('material')) then
                    mat = findloc(cfg%material_id, e%int('material'), dim=1)
                    if (mat == 0) then
                        call make_input_error(error, deck%file, e%line, 'wall', 'material '// &
                                              e%word('material')//' is not defined (no [particles] material record with '// &
                                              'this id)')
                        return
                    end if
                end if
                vx = e%real('vx')
                vy = e%real('vy')
                func = 0
                if (e%has('function')) then
                    func = findloc(function_ids, e%int('function'), dim=1)
                    if (func == 0) then
                        call unknown_function(deck, e, error)
                        return
                    end if
                end if
                ! Before the length: an end far out makes the model so large that the other
                ! walls would be blamed for their length.
                if (max(abs(e%real('x1')), abs(e%real('y1')), abs(e%real('x2')), abs(e%real('y2'))) > limit) then
                    call make_input_error(error, deck%file, e%line, 'wall', 'wall '// &
                                          to_str(i)//' has an end beyond the box the run can represent: '// &
                                          '|x|, |y| <= '//num(limit)//' m (4.5e9 times the smallest '// &
                                          'disk radius, at most 1e100 m): shorten it')
                    return
                end if
                length = hypot(e%real('x2') - e%real('x1'), e%real('y2') - e%real('y1'))
                if (length <= 1.0e-9_wp*size_model) then
                    if (length > 0.0_wp) then
                        call make_input_error(error, deck%file, e%line, 'wall', 'wall of length '// &
                                              length_text(length)//' m, below 1e-9 of the size of the model ('// &
                                              length_text(size_model)//' m, disks and walls): its ends cannot be '// &
                                              'told apart at that scale; check the coordinates of the model')
                    else
                        call make_input_error(error, deck%file, e%line, 'wall', &
                                              'zero-length wall: (x1, y1) and (x2, y2) coincide')
                    end if
                    return
                end if
                call check_repeated_wall(i, error)
                if (allocated(error)) return
                call walls_add(cfg%system%walls, e%real('x1'), e%real('y1'), e%real('x2'), e%real('y2'), &
                               error, mat=mat, vx=vx, vy=vy, func=func)
                if (allocated(error)) then
                    message = error%message
                    call make_input_error(error, deck%file, e%line, 'wall', message)
                    return
                end if
            end associate
        end do

    contains

        !> Error when wall i repeats an earlier one (the same ends, in either order): each
        !> would make its own contact with every disk on it, the reaction split between the
        !> two in a way no law decides, and the contact counts doubled (a line copied twice).
        subroutine check_repeated_wall(i, error)
            !> The wall's index in the deck's order.
            integer, intent(in) :: i
            !> Set when an earlier wall has the same ends.
            type(error_t), allocatable, intent(out) :: error
            real(wp) :: a(4), b(4)
            integer :: j
            a = [list(i)%real('x1'), list(i)%real('y1'), list(i)%real('x2'), list(i)%real('y2')]
            do j = 1, i - 1
                b = [list(j)%real('x1'), list(j)%real('y1'), list(j)%real('x2'), list(j)%real('y2')]
                if (all(a == b) .or. all(a == [b(3:4), b(1:2)])) then
                    call make_input_error(error, deck%file, list(i)%line, 'wall', 'this wall has the ends of '// &
                                          'the wall on line '//to_str(list(j)%line)//': each would make its own '// &
                                          'contacts with the disks on it; remove one')
                    return
                end if
            end do
        end subroutine check_repeated_wall
    end subroutine build_walls

    !> Size of the model: diagonal of the bounding box of the disks and wall ends [m].
    function model_size(cfg, walls) result(size_model)
        type(dem_config_t), intent(in) :: cfg
        type(deck_entry_t), intent(in) :: walls(:)
        real(wp) :: size_model
        real(wp) :: lo(2), hi(2)
        integer :: i
        associate (p => cfg%system%particles)
            lo = [minval(p%x(1:p%n) - p%radius(1:p%n)), minval(p%y(1:p%n) - p%radius(1:p%n))]
            hi = [maxval(p%x(1:p%n) + p%radius(1:p%n)), maxval(p%y(1:p%n) + p%radius(1:p%n))]
        end associate
        do i = 1, size(walls)
            associate (w => walls(i))
                lo = min(lo, [w%real('x1'), w%real('y1')], [w%real('x2'), w%real('y2')])
                hi = max(hi, [w%real('x1'), w%real('y1')], [w%real('x2'), w%real('y2')])
            end associate
        end do
        size_model = hypot(hi(1) - lo(1), hi(2) - lo(2))
    end function model_size

    !> Conditions on selections of disks: fixed and imposed DOFs (file order, no DOF
    !> constrained twice in conflicting ways), then forces and initial velocities (free DOFs
    !> only).
    subroutine build_conditions(deck, function_ids, cfg, error)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> Deck id of each time function.
        integer, intent(in) :: function_ids(:)
        !> The model (conditions, loads, initial velocities filled).
        type(dem_config_t), intent(inout) :: cfg
        !> Error, if any.
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: state(:, :), line(:, :), velocity_line(:)
        integer :: i, pass
        associate (n => cfg%system%particles%n)
            allocate (state(3, n), line(3, n), velocity_line(n))
        end associate
        state = free
        line = 0
        velocity_line = 0
        do pass = 1, 2
            do i = 1, size(deck%entries)
                associate (e => deck%entries(i))
                    if (e%section /= 'particles') cycle
                    select case (e%keyword)
                    case ('fix', 'velocity')
                        if (pass == 1) call constrain(e)
                    case ('force', 'initial_velocity')
                        if (pass == 2) call load(e)
                    case ('initial_rigid')
                        if (pass == 2) call rigid(e)
                    end select
                    if (allocated(error)) return
                end associate
            end do
        end do
        call check_kinetic_energy()

    contains

        !> The initial velocities' kinetic energy, disk by disk and in total, must be finite:
        !> a speed of 1e160 m/s (or a finite speed with a huge density) stopped the run at its
        !> initial state on an energy account that is not finite, blaming the forces or the time
        !> step. The error names the record that set the velocity of the disk with the largest
        !> energy.
        subroutine check_kinetic_energy()
            real(wp), allocatable :: energy(:)
            integer :: j
            associate (p => cfg%system%particles)
                if (p%n == 0) return
                energy = 0.5_wp*(p%mass(1:p%n)*(p%vx(1:p%n)**2 + p%vy(1:p%n)**2) + p%inertia(1:p%n)*p%w(1:p%n)**2)
                if (ieee_is_finite(sum(energy))) return
                j = maxloc(energy, dim=1, mask=.not. ieee_is_finite(energy))
                if (j == 0) j = maxloc(energy, dim=1)
                call make_input_error(error, deck%file, velocity_line(j), deck_keyword_at(velocity_line(j)), &
                                      'the kinetic energy of the initial velocities is beyond the range of '// &
                                      'double precision: disk '//to_str(j)//' (mass '//to_str(p%mass(j))// &
                                      ' kg/m) starts at ('//to_str(p%vx(j))//', '//to_str(p%vy(j))//') m/s and '// &
                                      to_str(p%w(j))//' rad/s; check the velocities (and the densities)')
            end associate
        end subroutine check_kinetic_energy

        !> Keyword of the [particles] record on a deck line.
        function deck_keyword_at(at) result(keyword)
            integer, intent(in) :: at
            character(len=:), allocatable :: keyword
            integer :: k
            keyword = ''
            do k = 1, size(deck%entries)
                if (deck%entries(k)%line == at) keyword = deck%entries(k)%keyword
            end do
        end function deck_keyword_at

        !> Selected disks of a record, as a range; error set when the selection is invalid.
        subroutine select_disks(e, first, last)
            type(deck_entry_t), intent(in) :: e
            integer, intent(out) :: first, last
            character(len=:), allocatable :: message
            logical :: ok
            call parse_selection(e%word('particles'), cfg%system%particles%n, first, last, ok, message, &
                                 'disks')
            if (.not. ok) call make_input_error(error, deck%file, e%line, e%keyword, message)
        end subroutine select_disks

        !> Time function index of the `function` value of a record (0 if absent); error if
        !> unknown.
        integer function function_of(e)
            type(deck_entry_t), intent(in) :: e
            function_of = 0
            if (.not. e%has('function')) return
            function_of = findloc(function_ids, e%int('function'), dim=1)
            if (function_of == 0) call unknown_function(deck, e, error)
        end function function_of

        !> A `fix` or `velocity` record.
        subroutine constrain(e)
            type(deck_entry_t), intent(in) :: e
            integer :: first, last, j, k, dof, func
            type(string_t), allocatable :: words(:)
            character(len=:), allocatable :: word
            call select_disks(e, first, last)
            if (allocated(error)) return
            if (e%keyword == 'fix') then
                words = e%words_from('dof')
                if (len(repeated_dof(words)) > 0) then
                    call make_input_error(error, deck%file, e%line, 'fix', 'the DOF '//repeated_dof(words)// &
                                          ' is named twice in this record (each of x, y, rot once, or all)')
                    return
                end if
                do k = 1, size(words)
                    word = words(k)%s
                    do dof = 1, 3
                        if (word /= 'all' .and. dof_index(word) /= dof) cycle
                        do j = first, last
                            if (state(dof, j) == imposed) then
                                call conflict(e, j, dof, 'cannot be fixed')
                                return
                            end if
                            if (state(dof, j) == fixed) cycle
                            call particles_fix(cfg%system%particles, j, dof, error)
                            if (allocated(error)) return
                            state(dof, j) = fixed
                            line(dof, j) = e%line
                        end do
                    end do
                end do
            else
                dof = dof_index(e%word('dof'))
                func = function_of(e)
                if (allocated(error)) return
                do j = first, last
                    if (state(dof, j) /= free) then
                        call conflict(e, j, dof, 'cannot also have an imposed velocity')
                        return
                    end if
                    call particles_impose_velocity(cfg%system%particles, j, dof, e%real('value'), &
                                                   error, func)
                    if (allocated(error)) return
                    state(dof, j) = imposed
                    line(dof, j) = e%line
                end do
            end if
        end subroutine constrain

        !> A `force` or `initial_velocity` record (free DOFs only).
        subroutine load(e)
            type(deck_entry_t), intent(in) :: e
            integer :: first, last, j, dof, func
            call select_disks(e, first, last)
            if (allocated(error)) return
            dof = dof_index(e%word('dof'))
            func = 0
            if (e%keyword == 'force') func = function_of(e)
            if (allocated(error)) return
            do j = first, last
                if (state(dof, j) /= free) then
                    call conflict(e, j, dof, 'takes no '//trim(merge('force           ', &
                                                                     'initial velocity', e%keyword == 'force'))// &
                                  ' (they apply to free DOFs only)')
                    return
                end if
                if (e%keyword == 'force') then
                    call particles_add_load(cfg%system%particles, j, dof, e%real('value'), error, func)
                    if (allocated(error)) return
                else
                    velocity_line(j) = e%line
                    select case (dof)
                    case (dof_x)
                        cfg%system%particles%vx(j) = e%real('value')
                    case (dof_y)
                        cfg%system%particles%vy(j) = e%real('value')
                    case default
                        cfg%system%particles%w(j) = e%real('value')
                    end select
                end if
            end do
        end subroutine load

        !> An `initial_rigid` record: selection vx vy omega xc yc gives each selected disk the
        !> velocity of a rigid motion, (vx - omega (y - yc), vy + omega (x - xc)) and the
        !> rotation rate omega; a DOF that is not free must get zero from it.
        subroutine rigid(e)
            type(deck_entry_t), intent(in) :: e
            integer :: first, last, j, dof
            real(wp) :: v(3)
            call select_disks(e, first, last)
            if (allocated(error)) return
            associate (p => cfg%system%particles)
                do j = first, last
                    v = [e%real('vx') - e%real('omega')*(p%y(j) - e%real('yc')), &
                         e%real('vy') + e%real('omega')*(p%x(j) - e%real('xc')), e%real('omega')]
                    do dof = 1, 3
                        if (state(dof, j) /= free .and. v(dof) /= 0.0_wp) then
                            call conflict(e, j, dof, 'cannot take the rigid velocity '//to_str(v(dof))// &
                                          ' (an initial velocity applies to free DOFs only)')
                            return
                        end if
                    end do
                    velocity_line(j) = e%line
                    if (state(dof_x, j) == free) p%vx(j) = v(1)
                    if (state(dof_y, j) == free) p%vy(j) = v(2)
                    if (state(dof_rot, j) == free) p%w(j) = v(3)
                end do
            end associate
        end subroutine rigid

        !> Error: DOF `dof` of disk j already has a condition.
        subroutine conflict(e, j, dof, what)
            type(deck_entry_t), intent(in) :: e
            integer, intent(in) :: j, dof
            character(len=*), intent(in) :: what
            character(len=:), allocatable :: now
            if (state(dof, j) == fixed) then
                now = 'is fixed'
            else
                now = 'has an imposed velocity'
            end if
            call make_input_error(error, deck%file, e%line, e%keyword, 'DOF '// &
                                  trim(dof_names(dof))//' of disk '//to_str(j)//' '//now//' (line '// &
                                  to_str(line(dof, j))//'): it '//trim(what))
        end subroutine conflict
    end subroutine build_conditions

    !> Contact laws: known materials, one law per pair.
    subroutine build_laws(deck, cfg, error)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> The model (material table filled).
        type(dem_config_t), intent(inout) :: cfg
        !> Error, if any.
        type(error_t), allocatable, intent(out) :: error
        type(deck_entry_t), allocatable :: list(:)
        integer, allocatable :: law_line(:, :)
        character(len=:), allocatable :: message
        integer :: i, a, b
        allocate (list, source=deck%records('contacts', 'law'))
        allocate (law_line(size(cfg%material_id), size(cfg%material_id)))
        law_line = 0
        if (.not. allocated(cfg%warnings)) allocate (cfg%warnings(0))
        do i = 1, size(list)
            associate (e => list(i))
                call material_pair(deck, cfg, e, 'law', law_line, a, b, error)
                if (allocated(error)) return
                if (e%has('rolling')) then
                    call materials_set_pair(cfg%system%materials, a, b, e%real('mu'), e%real('restitution'), &
                                            e%real('cohesion'), error, rolling=e%real('rolling'))
                else
                    call materials_set_pair(cfg%system%materials, a, b, e%real('mu'), e%real('restitution'), &
                                            e%real('cohesion'), error)
                end if
                if (allocated(error)) then
                    message = error%message
                    call make_input_error(error, deck%file, e%line, 'law', message)
                    return
                end if
                if (e%has('rolling')) call warn_rolling_length(e, a, b)
            end associate
        end do
        if (size(list) > 0) call warn_missing_laws(list(1)%line)
        call build_bonds(deck, cfg, law_line, error)
    contains
        !> Walls of a material that has a law with no material of the disks, or disks of a
        !> material that has one with no material of the walls, in a deck that gives laws to
        !> other pairs: their contacts are frictionless, without restitution or cohesion (the
        !> default), which is also what a forgotten record gives (an audit's floor of another
        !> material than its disks, silently frictionless). Pairs are not judged one by one:
        !> laws are often left out on purpose for bodies that never meet (the two disks and two
        !> inclines of input/incline.dat, each disk with its own incline's material), and so are
        !> laws between disks. Warned about at the first law's line, once per material.
        subroutine warn_missing_laws(line)
            integer, intent(in) :: line
            logical, allocatable :: on_disks(:), on_walls(:), wall_alone(:)
            integer :: a, b
            allocate (on_disks(size(cfg%material_id)), on_walls(size(cfg%material_id)), source=.false.)
            associate (p => cfg%system%particles, w => cfg%system%walls)
                on_disks(p%mat(1:p%n)) = .true.
                if (w%n > 0) on_walls(w%mat(1:w%n)) = .true.
            end associate
            allocate (wall_alone(size(cfg%material_id)), source=.false.)
            do b = 1, size(cfg%material_id)
                if (.not. on_walls(b) .or. any(law_line(:, b) > 0 .and. on_disks)) cycle
                wall_alone(b) = .true.
                call warn('the walls of material '//to_str(cfg%material_id(b))//' have no law with the disks of', &
                          on_disks, b, .true., line)
            end do
            ! disks without a law with any wall: unless every wall material is named already
            if (all(wall_alone .or. .not. on_walls)) return
            do a = 1, size(cfg%material_id)
                if (.not. on_disks(a) .or. any(law_line(a, :) > 0 .and. on_walls)) cycle
                call warn('the disks of material '//to_str(cfg%material_id(a))//' have no law with the walls of', &
                          on_walls, a, .false., line)
            end do
        end subroutine warn_missing_laws

        !> The warning for material `m`, whose bodies have no law with those of the materials
        !> flagged in `others` (`m` of walls when `walls`, of disks otherwise).
        subroutine warn(what, others, m, walls, line)
            character(len=*), intent(in) :: what
            logical, intent(in) :: others(:)
            integer, intent(in) :: m, line
            logical, intent(in) :: walls
            character(len=:), allocatable :: ids, first
            integer :: k
            ids = ''
            first = ''
            do k = 1, size(others)
                if (.not. others(k)) cycle
                if (len(first) == 0) first = to_str(cfg%material_id(k))
                ids = ids//', '//to_str(cfg%material_id(k))
            end do
            if (count(others) == 1) then
                ids = ', material '//ids(3:)
            else
                ids = ', materials '//ids(3:)
            end if
            if (walls) then
                first = first//' '//to_str(cfg%material_id(m))
            else
                first = to_str(cfg%material_id(m))//' '//first
            end if
            cfg%warnings = [cfg%warnings, string_t('warning: '//deck%file//':'//to_str(line)//': [contacts] '// &
                                                   what//' '//ids(3:)//': their contacts are '// &
                                                   'frictionless, without restitution or cohesion (the default); '// &
                                                   'add law = '//first//' 0 0 0 if that is meant')]
        end subroutine warn

        !> A rolling length beyond the radius of the largest disk of the pair's materials: the
        !> moment |M| <= e_r r_n then has an arm longer than the disk (e_r is a fraction of the
        !> radius in rolling-resistance models), and the sweeps may stop converging.
        subroutine warn_rolling_length(e, a, b)
            type(deck_entry_t), intent(in) :: e
            integer, intent(in) :: a, b
            real(wp) :: r_max
            associate (p => cfg%system%particles)
                ! (no disk of these materials: no radius to compare with)
                if (.not. any(p%mat(1:p%n) == a .or. p%mat(1:p%n) == b)) return
                r_max = maxval(p%radius(1:p%n), mask=p%mat(1:p%n) == a .or. p%mat(1:p%n) == b)
            end associate
            if (e%real('rolling') <= r_max) return
            cfg%warnings = [cfg%warnings, string_t('warning: '//deck%file//':'//to_str(e%line)//': [contacts] law: '// &
                                                   'the rolling length e_r = '//e%word('rolling')//' m exceeds the radius of '// &
                                                   'the largest disk of materials '//e%word('material1')//' and '// &
                                                   e%word('material2')//' ('//to_str(r_max)//' m): the moment''s arm is '// &
                                                   'longer than the disk (e_r is usually a fraction of the radius), and '// &
                                                   'the sweeps may not converge')]
        end subroutine warn_rolling_length
    end subroutine build_laws

    !> Materials (a, b) of a `law` or `bond` record: both defined, the pair given once (its
    !> line is recorded in `seen`).
    subroutine material_pair(deck, cfg, e, keyword, seen, a, b, error)
        type(deck_t), intent(in) :: deck
        type(dem_config_t), intent(in) :: cfg
        type(deck_entry_t), intent(in) :: e
        character(len=*), intent(in) :: keyword
        integer, intent(inout) :: seen(:, :)
        integer, intent(out) :: a, b
        type(error_t), allocatable, intent(out) :: error
        character(len=*), parameter :: fields(2) = ['material1', 'material2']
        integer :: k
        a = 0
        b = 0
        do k = 1, 2
            if (findloc(cfg%material_id, e%int(fields(k)), dim=1) == 0) then
                call make_input_error(error, deck%file, e%line, keyword, 'material '// &
                                      e%word(fields(k))//' is not defined (no [particles] material record with '// &
                                      'this id)')
                return
            end if
        end do
        a = findloc(cfg%material_id, e%int('material1'), dim=1)
        b = findloc(cfg%material_id, e%int('material2'), dim=1)
        if (seen(a, b) > 0) then
            call make_input_error(error, deck%file, e%line, keyword, 'the '//keyword//' between '// &
                                  'materials '//e%word('material1')//' and '//e%word('material2')//' is already given on '// &
                                  'line '//to_str(seen(a, b)))
            return
        end if
        seen(a, b) = e%line
        seen(b, a) = e%line
    end subroutine material_pair

    !> Bond bounds: a cohesive law for the pair, one bond record per pair.
    subroutine build_bonds(deck, cfg, law_line, error)
        type(deck_t), intent(in) :: deck
        type(dem_config_t), intent(inout) :: cfg
        integer, intent(in) :: law_line(:, :)
        type(error_t), allocatable, intent(out) :: error
        type(deck_entry_t), allocatable :: list(:)
        integer, allocatable :: bond_line(:, :)
        character(len=:), allocatable :: message
        real(wp) :: e_b
        integer :: i, a, b
        allocate (list, source=deck%records('contacts', 'bond'))
        allocate (bond_line(size(cfg%material_id), size(cfg%material_id)))
        bond_line = 0
        do i = 1, size(list)
            associate (e => list(i))
                call material_pair(deck, cfg, e, 'bond', bond_line, a, b, error)
                if (allocated(error)) return
                if (law_line(a, b) == 0) then
                    call make_input_error(error, deck%file, e%line, 'bond', 'materials '//e%word('material1')// &
                                          ' and '//e%word('material2')//' have no law: give them a [contacts] law with '// &
                                          'cohesion > 0, or the bond would never form')
                    return
                end if
                if (.not. cfg%system%materials%cohesion(a, b) > 0.0_wp) then
                    call make_input_error(error, deck%file, e%line, 'bond', 'the law of materials '// &
                                          e%word('material1')//' and '//e%word('material2')//' (line '//to_str(law_line(a, b))// &
                                          ') has no cohesion: bonds form only between cohesive materials')
                    return
                end if
                e_b = bond_e_default
                if (e%has('e_b')) e_b = e%real('e_b')
                call materials_set_bond(cfg%system%materials, a, b, e%real('mu_b'), e_b, error)
                if (allocated(error)) then
                    message = error%message
                    call make_input_error(error, deck%file, e%line, 'bond', message)
                    return
                end if
            end associate
        end do
    end subroutine build_bonds

    !> Time stepping, detection, solver and output settings.
    subroutine build_settings(deck, run, cfg, error)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> Run settings (time step).
        type(run_config_t), intent(in) :: run
        !> The model (scheme, solver, store_contacts filled).
        type(dem_config_t), intent(inout) :: cfg
        !> Internal error on a word that the schema allows and no kind here builds.
        type(error_t), allocatable, intent(out) :: error
        associate (sys => cfg%system)
            sys%scheme%h = run%h
            sys%scheme%theta = deck%get_real('time', 'theta')
            if (allocated(sys%scheme%activation)) deallocate (sys%scheme%activation)
            select case (deck%get_word('time', 'contact_scheme'))
            case ('multicor')
                allocate (activation_predicted_t :: sys%scheme%activation)
            case ('siconos')
                allocate (activation_siconos_t :: sys%scheme%activation)
            case default
                call unknown_word('time', 'contact_scheme')
                return
            end select
            cfg%default_alert = .not. deck%has('contacts', 'alert')
            if (cfg%default_alert) then
                sys%scheme%alert = default_alert_ratio* &
                                   sum(sys%particles%radius(1:sys%particles%n))/real(sys%particles%n, wp)
            else
                sys%scheme%alert = deck%get_real('contacts', 'alert')
                if (.not. sys%scheme%alert > 0.0_wp) call warn_zero_alert()
            end if
            sys%solver%tol = deck%get_real('solver', 'tolerance')
            sys%solver%max_sweeps = deck%get_int('solver', 'max_sweeps')
            sys%solver%local_tol = deck%get_real('solver', 'local_tolerance')
            sys%solver%local_max_iter = deck%get_int('solver', 'local_iterations')
            if (allocated(sys%method)) deallocate (sys%method)
            select case (deck%get_word('solver', 'method'))
            case ('nlgs')
                allocate (sweeps_method_t :: sys%method)
            case ('block')
                allocate (bonded_block_method_t :: sys%method)
            case ('coarse')
                ! the sweeps (nlgs) with the coarse correction
                allocate (sweeps_method_t :: sys%method)
                allocate (sys%solver%correction, source=coarse_correction_t(every=deck%get_int('solver', 'coarse_every'), &
                                                                            aggregate=deck%get_int('solver', 'coarse_size')))
            case default
                call unknown_word('solver', 'method')
                return
            end select
            sys%solver%relaxation = deck%get_real('solver', 'relaxation')
            sys%solver%check_every = deck%get_int('solver', 'check_every')
            sys%solver%anderson = deck%get_int('solver', 'anderson')
            sys%solver%anderson_after = deck%get_int('solver', 'anderson_after')
            sys%solver%anderson_sweeps = deck%get_int('solver', 'anderson_sweeps')
            if (deck%get_word('solver', 'cold_start') == 'hydrostatic') allocate (hydrostatic_start_t :: sys%solver%start)
            sys%solver%symmetric = deck%get_word('solver', 'sweep_order') == 'alternating'
            if (allocated(sys%solver%criterion)) deallocate (sys%solver%criterion)
            select case (deck%get_word('solver', 'criterion'))
            case ('lmgc90')
                allocate (lmgc90_criterion_t :: sys%solver%criterion)
            case ('siconos')
                allocate (siconos_criterion_t :: sys%solver%criterion)
            case default
                call unknown_word('solver', 'criterion')
                return
            end select
            if (deck%has('solver', 'fclib_step')) cfg%fclib_step = deck%get_int('solver', 'fclib_step')
        end associate
        cfg%store_contacts = deck%get_word('output', 'contacts') == 'yes'
    contains
        ! [contacts] alert = 0: the detection reaches no further than the round-off allowance
        subroutine warn_zero_alert()
            if (.not. allocated(cfg%warnings)) allocate (cfg%warnings(0))
            cfg%warnings = [cfg%warnings, string_t('warning: '//deck%file//':'//to_str(deck%line('contacts', 'alert'))// &
                                                   ': [contacts] alert = 0: a contact is seen only once its disks '// &
                                                   'touch or overlap, so an approaching pair is found a step late '// &
                                                   'and overlaps; give a positive alert distance (the default is '// &
                                                   'a quarter of the mean radius) or leave the keyword out')]
        end subroutine warn_zero_alert

        ! the schema refuses a word outside its list: one it allows that no case here builds is
        ! a bug (a word added to the schema without its kind)
        subroutine unknown_word(section, keyword)
            character(len=*), intent(in) :: section, keyword
            call make_internal_error(error, 'driver_config_dem', '['//section//'] '//keyword//" = '"// &
                                     deck%get_word(section, keyword)//"' builds no kind")
        end subroutine unknown_word
    end subroutine build_settings

    !> Error when two disks, or a disk and a wall, overlap at t = 0 by more than
    !> overlap_tolerance times their mean radius (touching is fine).
    subroutine check_overlaps(deck, cfg, error)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> The model.
        type(dem_config_t), intent(in) :: cfg
        !> Error naming the pair, if any.
        type(error_t), allocatable, intent(out) :: error
        type(detector_t) :: det
        type(contact_set_t) :: cs
        real(wp) :: amoy
        integer :: k, a, b
        associate (p => cfg%system%particles, w => cfg%system%walls)
            if (w%n > 0) then
                call detect_contacts(det, p%x(1:p%n), p%y(1:p%n), p%radius(1:p%n), 0.0_wp, &
                                     w%x1(1:w%n), w%y1(1:w%n), w%x2(1:w%n), w%y2(1:w%n), cs)
            else
                call detect_contacts(det, p%x(1:p%n), p%y(1:p%n), p%radius(1:p%n), 0.0_wp, &
                                     [real(wp) ::], [real(wp) ::], [real(wp) ::], [real(wp) ::], cs)
            end if
            do k = 1, cs%n
                a = cs%i1(k)
                b = cs%i2(k)
                amoy = p%radius(b)
                if (a > 0) amoy = 0.5_wp*(p%radius(a) + p%radius(b))
                if (cs%gap(k) >= -overlap_tolerance*amoy) cycle
                if (a > 0) then
                    call make_input_error(error, deck%file, &
                                          max(cfg%disk_line(a), cfg%disk_line(b)), '', 'disks '//to_str(min(a, b))// &
                                          ' (line '//to_str(cfg%disk_line(min(a, b)))//') and '//to_str(max(a, b))// &
                                          ' (line '//to_str(cfg%disk_line(max(a, b)))//') overlap by '// &
                                          length_text(-cs%gap(k))//' m at t = 0: move them apart')
                else
                    call make_input_error(error, deck%file, cfg%wall_line(-a), 'wall', 'disk '// &
                                          to_str(b)//' (line '//to_str(cfg%disk_line(b))//') overlaps wall '// &
                                          to_str(-a)//' by '//length_text(-cs%gap(k))//' m at t = 0: move it off '// &
                                          'the wall')
                end if
                return
            end do
        end associate
    end subroutine check_overlaps

    !> A length with 4 significant digits, e.g. '5.000E-03' ('1.000E+300').
    function length_text(x) result(text)
        !> The length [m].
        real(wp), intent(in) :: x
        character(len=:), allocatable :: text
        text = sci_to_str(x, 3)
    end function length_text

    !> Error for a record whose `function` value is the id of no time function.
    subroutine unknown_function(deck, e, error)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> The record.
        type(deck_entry_t), intent(in) :: e
        !> The error.
        type(error_t), allocatable, intent(out) :: error
        call make_input_error(error, deck%file, e%line, e%keyword, 'function '//e%word('function')// &
                              ' is not defined (no [functions] function record with this id)')
    end subroutine unknown_function

    !> DOF index of a DOF word: x, y, rot or their [beam] names u, w, theta.
    pure integer function dof_index(word)
        !> 'x' or 'u', 'y' or 'w', 'rot' or 'theta'.
        character(len=*), intent(in) :: word
        select case (word)
        case ('x', 'u')
            dof_index = dof_x
        case ('y', 'w')
            dof_index = dof_y
        case default
            dof_index = dof_rot
        end select
    end function dof_index
end module driver_config_dem
