!> From a validated deck with [beam], [particles] and [coupling] to the description of the
!> Arlequin coupling (`coupling_arlequin::coupling_config_t`), with the checks across
!> sections that the library would otherwise report without a deck line:
!> - a coupled run is a time integration (analysis = dynamic);
!> - the schemes: the coupling exchanges the impulse h ((1 - gamma) lambda_n + gamma
!>   lambda_{n+1}) between the beam (Newmark) and the disks (Moreau-Jean), which is exact in
!>   momentum and energy only with average acceleration (beta = 1/4, gamma = 1/2) and
!>   theta = 1/2 (doc/theory.md section 6.5, coupling_arlequin). Another beta or gamma (or the
!>   explicit central difference, whose lumped, undamped beta = 0 predictor the multiplier
!>   matrix does not model) is an error; theta > 1/2 is accepted with a warning (the
!>   constraint still holds, but the balance then shows the scheme's numerical dissipation
!>   and a net coupling work of order h);
!> - the overlap lies on the beam (0 <= s <= length along the elements) and is not empty;
!> - every disk centre lies beyond s_fe (a disk in the FE-only zone would get alpha = 1, a
!>   zero weighted mass);
!> - listed coupled disks exist, are listed once, and lie inside the overlap (alpha strictly
!>   between 0 and 1), within max_offset of the axis when it is given; with coupled = auto at
!>   least one disk centre lies in the overlap;
!> - thickness within a factor 100 of the beam section's width (`warn_thickness`, a warning);
!> - without max_offset, a coupled disk off the beam's section (farther from the axis than its
!>   radius plus the section's half-height) is warned about (`warn_far_disks`).
!> Each error names the deck file, the line and the keyword concerned, and the disk by its
!> number and the line that created it.
module driver_config_coupling
    use core_kinds, only: wp
    use core_constants, only: relative_roundoff
    use core_error, only: error_t, make_input_error
    use core_strings, only: string_t, to_str
    use io_memory, only: available_memory
    use io_deck, only: deck_t, deck_entry_t
    use io_deck_schema, only: parse_selection
    use fem_beam_config, only: beam_config_t
    use fem_beam_model, only: beam_model_t, build_beam_model
    ! The deck checks project disks on the beam exactly as the coupling library does.
    use fem_beam_projection, only: beam_point_t, project_on_beam
    use coupling_weights, only: weight_config_t, overlap_weight_t, make_weight
    use coupling_arlequin, only: coupling_config_t, multipliers_particles, multipliers_nodes
    use driver_config, only: run_config_t
    use driver_config_dem, only: dem_config_t
    implicit none
    private
    public :: coupled_setup_t, build_coupling_config

    !> The coupling of a deck, with what the driver reports and stores about it.
    type :: coupled_setup_t
        !> Description handed to coupling_arlequin::build_coupled_system.
        type(coupling_config_t) :: config
        !> Deck line of the overlap keyword (messages of the library are attached to it).
        integer :: overlap_line = 0
        !> Warnings to report before the run (e.g. theta > 1/2).
        type(string_t), allocatable :: warnings(:)
    end type coupled_setup_t

contains

    !> Line of the first gravity record, [beam] or [particles] (0 when neither has one).
    pure integer function first_gravity_line(deck) result(line)
        !> The deck.
        type(deck_t), intent(in) :: deck
        integer :: i
        line = 0
        do i = 1, size(deck%entries)
            if (deck%entries(i)%keyword /= 'gravity') cycle
            line = deck%entries(i)%line
            return
        end do
    end function first_gravity_line

    !> Build and check the coupling of a deck with [beam], [particles] and [coupling].
    subroutine build_coupling_config(deck, run, beam, dem, setup, error)
        !> Deck read with the MULTICOR schema.
        type(deck_t), intent(in) :: deck
        !> Run settings (driver_config::build_config).
        type(run_config_t), intent(in) :: run
        !> The beam (driver_config::build_config).
        type(beam_config_t), intent(in) :: beam
        !> The particles (driver_config_dem::build_dem_config).
        type(dem_config_t), intent(in) :: dem
        !> The coupling.
        type(coupled_setup_t), intent(out) :: setup
        !> Error naming file, line and keyword, if any.
        type(error_t), allocatable, intent(out) :: error
        type(beam_model_t) :: model
        type(overlap_weight_t) :: weight
        type(beam_point_t) :: at
        real(wp), allocatable :: s(:), off(:)
        integer :: first_line, i
        allocate (setup%warnings(0))
        first_line = coupling_first_line(deck)
        call check_schemes(deck, run, setup, error)
        if (allocated(error)) return
        ! Both sides of the overlap must carry the same self-weight (each weighted by its share
        ! of the Arlequin partition), else the overlap is loaded on one side only.
        if (any(dem%system%particles%gravity /= beam%gravity)) then
            call make_input_error(error, deck%file, first_gravity_line(deck), 'gravity', &
                                  'coupled runs need the same gravity in [beam] and [particles] (the '// &
                                  'two models share the weight in the overlap): [beam] gravity = '// &
                                  to_str(beam%gravity(1))//' '//to_str(beam%gravity(2))// &
                                  ', [particles] gravity = '//to_str(dem%system%particles%gravity(1))// &
                                  ' '//to_str(dem%system%particles%gravity(2)))
            return
        end if
        if (deck%has('coupling', 'region')) then
            call make_input_error(error, deck%file, deck%line('coupling', 'region'), 'region', &
                                  'region lines define the overlap of a [continuum]; a beam takes overlap = '// &
                                  's_fe s_particle')
            return
        end if
        call require(deck, 'overlap', first_line, 's_fe s_particle [m]', error)
        if (allocated(error)) return
        call require(deck, 'thickness', first_line, 'depth of the disks [m], usually the '// &
                     'width of the beam section', error)
        if (allocated(error)) return
        setup%overlap_line = deck%line('coupling', 'overlap')
        associate (c => setup%config)
            c%weight = weight_config_t(shape=deck%get_word('coupling', 'weight'), &
                                       s_fe=deck%get_real('coupling', 'overlap', 's_fe'), &
                                       s_particle=deck%get_real('coupling', 'overlap', 's_particle'), &
                                       alpha_min=deck%get_real('coupling', 'alpha_min'), &
                                       constant=deck%get_real('coupling', 'constant'))
            c%thickness = deck%get_real('coupling', 'thickness')
            c%memory_limit = available_memory()
            c%rotation_row = deck%get_word('coupling', 'rotation') == 'on'
            c%max_offset = deck%get_real('coupling', 'max_offset')
            c%multipliers = merge(multipliers_nodes, multipliers_particles, &
                                  deck%get_word('coupling', 'multipliers') == 'nodes')
        end associate
        call warn_thickness(deck, beam, setup)
        ! The unweighted beam gives the abscissas (it was built without error before).
        call build_beam_model(beam, model, error)
        if (allocated(error)) return
        call check_overlap(deck, setup, model, error)
        if (allocated(error)) return
        call make_weight(setup%config%weight, weight, error)
        if (allocated(error)) then
            ! the value at fault: constant (when given), else the overlap it weights
            if (index(error%message, 'constant =') > 0 .and. deck%has('coupling', 'constant')) then
                call reattach(deck, deck%line('coupling', 'constant'), 'constant', error)
            else
                call reattach(deck, setup%overlap_line, 'overlap', error)
            end if
            return
        end if
        associate (p => dem%system%particles)
            allocate (s(p%n), off(p%n))
            do i = 1, p%n
                at = project_on_beam(model, p%x(i), p%y(i))
                s(i) = at%abscissa
                off(i) = at%offset()
            end do
        end associate
        call check_fe_zone(deck, setup, weight, dem, s, error)
        if (allocated(error)) return
        call select_coupled(deck, setup, weight, dem, s, off, model%ea, model%ei, error)
    end subroutine build_coupling_config

    !> A warning when [coupling] thickness is more than `ratio` times off the width of every
    !> section of the beam: a depth typed in mm instead of m makes the disks' masses and
    !> forces (per unit thickness) 1000 times too large, and nothing else catches it. The
    !> section gives A and I, not its width: the width taken is that of the rectangle with
    !> the same A and I, A / sqrt(12 I / A). It differs from the depth a user means by a
    !> factor of a few for other shapes (an I-section's flanges: about 10 for an IPE 200, a
    !> thin tube of radius 20 times its wall: about 15), hence the wide `ratio`.
    subroutine warn_thickness(deck, beam, setup)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> The beam (its sections).
        type(beam_config_t), intent(in) :: beam
        !> The coupling: the warning is added to its warnings.
        type(coupled_setup_t), intent(inout) :: setup
        real(wp), parameter :: ratio = 100.0_wp
        real(wp), allocatable :: width(:)
        character(len=:), allocatable :: message
        integer :: k
        if (.not. allocated(beam%sections)) return
        if (size(beam%sections) == 0) return
        allocate (width(size(beam%sections)))
        do k = 1, size(beam%sections)
            associate (a => beam%sections(k)%area, i => beam%sections(k)%inertia)
                width(k) = a/sqrt(12*i/a)
            end associate
        end do
        associate (t => setup%config%thickness)
            if (t <= ratio*maxval(width) .and. t >= minval(width)/ratio) return
            message = 'warning: '//deck%file//':'//to_str(deck%line('coupling', 'thickness'))// &
                      ': [coupling] thickness = '//to_str(t)//' m is more than '//to_str(ratio)// &
                      ' times off the width of the beam''s section ('//to_str(minval(width))
            if (maxval(width) > minval(width)) message = message//' to '//to_str(maxval(width))
            message = message//' m, the width of the rectangle with its A and I): the disks'' masses '// &
                      'and forces scale with thickness (per unit thickness); check its unit (m)'
        end associate
        setup%warnings = [setup%warnings, string_t(message)]
    end subroutine warn_thickness

    !> First line of the [coupling] entries (0 if none).
    pure integer function coupling_first_line(deck) result(line)
        type(deck_t), intent(in) :: deck
        integer :: i
        line = 0
        do i = 1, size(deck%entries)
            if (deck%entries(i)%section /= 'coupling') cycle
            line = deck%entries(i)%line
            return
        end do
    end function coupling_first_line

    !> Error when a keyword a coupled deck needs is absent.
    subroutine require(deck, keyword, line, hint, error)
        type(deck_t), intent(in) :: deck
        character(len=*), intent(in) :: keyword, hint
        integer, intent(in) :: line
        type(error_t), allocatable, intent(out) :: error
        if (deck%has('coupling', keyword)) return
        call make_input_error(error, deck%file, line, keyword, 'missing: a coupled deck '// &
                              'needs [coupling] '//keyword//' = '//hint)
    end subroutine require

    !> Analysis and time schemes of a coupled run (see the module description).
    subroutine check_schemes(deck, run, setup, error)
        type(deck_t), intent(in) :: deck
        type(run_config_t), intent(in) :: run
        type(coupled_setup_t), intent(inout) :: setup
        type(error_t), allocatable, intent(out) :: error
        real(wp) :: theta
        character(len=:), allocatable :: message
        character(len=*), parameter :: why = 'the coupling exchanges the impulse h ((1 - '// &
                                       'gamma) lambda_n + gamma lambda_{n+1}) between the beam and the disks, which '// &
                                       'conserves momentum and energy only with beta = 1/4, gamma = 1/2 and theta = 1/2'
        if (run%analysis /= 'dynamic') then
            call make_input_error(error, deck%file, deck%line('run', 'analysis'), 'analysis', &
                                  'a coupled run (beam, particles and [coupling]) is a time integration: set '// &
                                  'analysis = dynamic (the particles have no '//run%analysis//' analysis)')
            return
        end if
        if (run%scheme == 'central_difference') then
            call make_input_error(error, deck%file, deck%line('time', 'scheme'), 'scheme', &
                                  'coupled runs need the implicit average-acceleration scheme for the beam '// &
                                  '(the multipliers are solved with the effective matrix M + h^2 K / 4): set '// &
                                  'scheme = average_acceleration; '//why)
            return
        end if
        if (abs(run%beta - 0.25_wp) > 0 .or. abs(run%gamma - 0.5_wp) > 0) then
            call make_input_error(error, deck%file, deck%line('time', 'scheme'), 'scheme', &
                                  'coupled runs need beta = 0.25 and gamma = 0.5 (here beta = '// &
                                  to_str(run%beta)//', gamma = '//to_str(run%gamma)//'): set scheme = '// &
                                  'average_acceleration; '//why)
            return
        end if
        theta = deck%get_real('time', 'theta')
        if (abs(theta - 0.5_wp) > 0) then
            message = 'warning: '//deck%file//':'//to_str(deck%line('time', 'theta'))// &
                      ': [time] theta = '//to_str(theta)//' in a coupled run: the constraint '// &
                      'q = C u still holds, but the particles dissipate numerically and the '// &
                      'coupling does a net work of order h, so /coupling/energy/balance does not '// &
                      'close; '//why
            setup%warnings = [setup%warnings, string_t(message)]
        end if
    end subroutine check_schemes

    !> The overlap lies on the beam: both ends within [0, length].
    subroutine check_overlap(deck, setup, model, error)
        type(deck_t), intent(in) :: deck
        type(coupled_setup_t), intent(in) :: setup
        type(beam_model_t), intent(in) :: model
        type(error_t), allocatable, intent(out) :: error
        real(wp) :: length, ends(2)
        integer :: k
        character(len=*), parameter :: names(2) = ['s_fe      ', 's_particle']
        length = maxval(model%abscissa)
        ends = [setup%config%weight%s_fe, setup%config%weight%s_particle]
        do k = 1, 2
            if (ends(k) <= length*(1 + relative_roundoff)) cycle
            call make_input_error(error, deck%file, setup%overlap_line, 'overlap', &
                                  trim(names(k))//' = '//to_str(ends(k))//' m lies beyond the end of the beam '// &
                                  '(abscissas along the beam run from 0 at its first node to '// &
                                  to_str(length)//' m): the overlap must lie on the beam')
            return
        end do
        if (.not. (abs(ends(2) - ends(1)) > 0)) then
            call make_input_error(error, deck%file, setup%overlap_line, 'overlap', &
                                  'the overlap is empty (s_fe = s_particle = '//to_str(ends(1))//' m)')
        end if
    end subroutine check_overlap

    !> No disk centre in the FE-only zone (alpha = 1: zero weighted mass).
    subroutine check_fe_zone(deck, setup, weight, dem, s, error)
        type(deck_t), intent(in) :: deck
        type(coupled_setup_t), intent(in) :: setup
        type(overlap_weight_t), intent(in) :: weight
        type(dem_config_t), intent(in) :: dem
        real(wp), intent(in) :: s(:)
        type(error_t), allocatable, intent(out) :: error
        integer :: i
        do i = 1, size(s)
            if (weight%value(s(i)) < 1) cycle
            call make_input_error(error, deck%file, setup%overlap_line, 'overlap', 'disk '// &
                                  to_str(i)//' (line '//to_str(dem%disk_line(i))//', abscissa '//to_str(s(i))// &
                                  ' m along the beam) lies in the FE-only zone, on the FE side of s_fe = '// &
                                  to_str(weight%s_fe)//' m, where alpha = 1 would leave it no mass: move s_fe '// &
                                  'past it, or remove the disk')
            return
        end do
    end subroutine check_fe_zone

    !> The coupled disks: `auto` or selections, checked against the overlap.
    subroutine select_coupled(deck, setup, weight, dem, s, off, beam_ea, beam_ei, error)
        type(deck_t), intent(in) :: deck
        type(coupled_setup_t), intent(inout) :: setup
        type(overlap_weight_t), intent(in) :: weight
        type(dem_config_t), intent(in) :: dem
        real(wp), intent(in) :: s(:), off(:)
        ! axial and bending stiffnesses EA and EI of the beam's elements
        real(wp), intent(in) :: beam_ea(:), beam_ei(:)
        type(error_t), allocatable, intent(out) :: error
        type(deck_entry_t) :: e
        type(string_t), allocatable :: selections(:)
        integer, allocatable :: list(:)
        character(len=:), allocatable :: message
        real(wp) :: alpha, max_offset
        integer :: k, first, last, i, n, line
        logical :: ok, auto
        n = size(s)
        max_offset = setup%config%max_offset
        e = deck%record('coupling', 'coupled', 1)
        line = e%line
        auto = e%n_values() == 0
        if (.not. auto) auto = e%word('coupled') == 'auto'
        if (auto) then
            if (e%n_values() > 1) then
                call make_input_error(error, deck%file, line, 'coupled', "'auto' stands alone:"// &
                                      ' write coupled = auto, or a list of selections of disks')
                return
            end if
            list = pack([(i, i=1, n)], [(in_overlap(i) .and. (max_offset <= 0 .or. abs(off(i)) <= max_offset), &
                                         i=1, n)])
            if (size(list) > 0) then
                call warn_far_disks(list)
                return
            end if
            message = ''
            if (max_offset > 0) message = ' within max_offset = '//to_str(max_offset)// &
                                          ' m of the axis'
            call make_input_error(error, deck%file, setup%overlap_line, 'overlap', 'no disk '// &
                                  'centre lies in the overlap ['//to_str(weight%s_fe)//', '// &
                                  to_str(weight%s_particle)//'] m'//message//': nothing to couple')
            return
        end if
        allocate (list(0))
        selections = e%words_from('coupled')
        do k = 1, size(selections)
            call parse_selection(selections(k)%s, n, first, last, ok, message, 'disks')
            if (.not. ok) then
                call make_input_error(error, deck%file, line, 'coupled', message// &
                                      " (or 'auto')")
                return
            end if
            do i = first, last
                if (any(list == i)) then
                    call make_input_error(error, deck%file, line, 'coupled', 'disk '// &
                                          to_str(i)//' is selected twice')
                    return
                end if
                alpha = weight%value(s(i))
                if (.not. (alpha > 0 .and. alpha < 1)) then
                    call make_input_error(error, deck%file, line, 'coupled', 'disk '// &
                                          to_str(i)//' (line '//to_str(dem%disk_line(i))//', abscissa '// &
                                          to_str(s(i))//' m along the beam) is outside the overlap ['// &
                                          to_str(weight%s_fe)//', '//to_str(weight%s_particle)//'] m: its '// &
                                          'weight alpha = '//to_str(alpha)//' would leave it no mass on one '// &
                                          'side of the coupling (a singular multiplier system); couple only '// &
                                          'disks inside the overlap')
                    return
                end if
                if (max_offset > 0 .and. abs(off(i)) > max_offset) then
                    call make_input_error(error, deck%file, line, 'coupled', 'disk '// &
                                          to_str(i)//' (line '//to_str(dem%disk_line(i))//') is '// &
                                          to_str(abs(off(i)))//' m from the beam axis, more than max_offset = '// &
                                          to_str(max_offset)//' m')
                    return
                end if
                list = [list, i]
            end do
        end do
        setup%config%particles = list
        call warn_far_disks(list)

    contains

        !> Whether disk i lies inside the overlap (0 < alpha < 1).
        logical function in_overlap(i)
            integer, intent(in) :: i
            real(wp) :: a
            a = weight%value(s(i))
            in_overlap = a > 0 .and. a < 1
        end function in_overlap

        !> With no max_offset, a warning when a coupled disk lies off the beam's section.
        !> The coupling glues a disk to the section at its abscissa through a rigid arm of its
        !> offset: the disk stands for material of that section only when it touches it, its
        !> centre within its radius plus the section's half-height of the axis. The section
        !> gives A and I, not its height: the half-height taken is that of the rectangle with
        !> the same A and I, sqrt(3 I / A) (the largest over the beam's elements; a rectangle
        !> is exact, an I-section's flanges sit within it, a solid circle's rim is 15 % beyond
        !> it). A disk farther out is glued to nothing it touches: accepted, but warned about.
        subroutine warn_far_disks(coupled)
            integer, intent(in) :: coupled(:)
            real(wp) :: half_height, reach
            integer :: far, i, beyond, at
            if (max_offset > 0 .or. size(coupled) == 0) return
            half_height = sqrt(3*maxval(beam_ei/beam_ea))
            beyond = 0
            far = 0
            do i = 1, size(coupled)
                associate (k => coupled(i))
                    if (abs(off(k)) <= dem%system%particles%radius(k) + half_height) cycle
                    beyond = beyond + 1
                    if (far == 0) far = k
                    if (abs(off(k)) > abs(off(far))) far = k
                end associate
            end do
            if (beyond == 0) return
            reach = dem%system%particles%radius(far) + half_height
            at = deck%line('coupling', 'coupled')
            if (at == 0) at = setup%overlap_line
            message = 'warning: '//deck%file//':'//to_str(at)//': [coupling] '//to_str(beyond)//' of the '// &
                      to_str(size(coupled))//' coupled disks lie off the beam''s section; the farthest, disk '// &
                      to_str(far)//' (line '//to_str(dem%disk_line(far))//'), is '//to_str(abs(off(far)))// &
                      ' m from the beam axis, beyond its radius plus the section''s half-height ('// &
                      to_str(reach)//' m; half-height sqrt(3 I / A) = '//to_str(half_height)//' m): it is '// &
                      'glued to the beam through a rigid arm of that length without touching it; set '// &
                      '[coupling] max_offset (e.g. '//to_str(reach)//' m) to couple only the disks on the beam, '// &
                      'or check the disks'' positions'
            setup%warnings = [setup%warnings, string_t(message)]
        end subroutine warn_far_disks
    end subroutine select_coupled

    !> Prefix a library error with the deck file, line and keyword.
    subroutine reattach(deck, line, keyword, error)
        type(deck_t), intent(in) :: deck
        integer, intent(in) :: line
        character(len=*), intent(in) :: keyword
        type(error_t), allocatable, intent(inout) :: error
        character(len=:), allocatable :: message
        message = error%message
        call make_input_error(error, deck%file, line, keyword, message)
    end subroutine reattach
end module driver_config_coupling
