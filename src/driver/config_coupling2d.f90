!> From a validated deck with [continuum], [particles] and [coupling] to the description of the
!> 2D Arlequin coupling (`coupling_arlequin2d::coupling2d_config_t`), read by keyword name, with
!> the checks across sections:
!> - a coupled run is a time integration (analysis = dynamic) with average acceleration
!>   (beta = 1/4, gamma = 1/2) and theta = 1/2 (another theta: a warning), as for the beam;
!> - the overlap is given by `region` lines (box or polygon, at least one); the beam's
!>   `overlap`, `max_offset` and `coupled` have no meaning here and are refused;
!> - [continuum] gravity and [particles] gravity agree (both sides carry their weighted share
!>   of the weight in the overlap);
!> - a polygon's edge numbers are integers within its edges;
!> - the regions are disjoint (they may share edges): a common area would be weighted twice;
!> - thickness is that of the continuum's material under the regions (else a warning).
!> Errors name the deck file, the line and the keyword.
module driver_config_coupling2d
    use core_kinds, only: wp
    use core_constants, only: relative_roundoff
    use core_error, only: error_t, make_input_error
    use core_strings, only: string_t, to_str
    use io_memory, only: available_memory
    use io_deck, only: deck_t, deck_entry_t
    use coupling_weights, only: weight_config_t
    use coupling_overlap2d, only: overlap2d_t, overlap_set_t, make_box_overlap, make_polygon_overlap, &
                                  regions_overlap
    use coupling_operator2d, only: pairing_l2, pairing_h1
    use coupling_coupled_step, only: multipliers_particles, multipliers_nodes
    use fem_mass_scheme, only: make_mass_scheme
    use fem_continuum_model, only: continuum_model_t
    use coupling_arlequin2d, only: coupling2d_config_t
    implicit none
    private
    public :: coupled2d_setup_t, build_coupling2d_config, check_coupled2d_scheme

    !> Why a coupled run needs average acceleration and theta = 1/2.
    character(len=*), parameter :: scheme_why = 'the coupling exchanges the impulse h ((1 - gamma) '// &
                                   'lambda_n + gamma lambda_{n+1}) between the continuum and the '// &
                                   'disks, which conserves momentum and energy only with beta = 1/4, '// &
                                   'gamma = 1/2 and theta = 1/2'

    !> The 2D coupling of a deck, with what the driver reports about it.
    type :: coupled2d_setup_t
        !> Description handed to coupling_arlequin2d::build_coupled2d.
        type(coupling2d_config_t) :: config
        !> Deck line of the first region (messages of the library are attached to it).
        integer :: region_line = 0
        !> Warnings to report before the run (e.g. theta > 1/2).
        type(string_t), allocatable :: warnings(:)
    end type coupled2d_setup_t

contains

    !> A coupled run of a continuum and disks is a time integration with average acceleration
    !> (Newmark beta = 1/4, gamma = 1/2): checked on the deck before the continuum is built,
    !> whose own checks (the lumped mass and the critical step of central differences) would
    !> otherwise come first and ask for changes that this check then refuses.
    subroutine check_coupled2d_scheme(deck, error)
        !> Deck read with the MULTICOR schema.
        type(deck_t), intent(in) :: deck
        !> Error naming file, line and keyword, if any.
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: scheme
        logical :: ok
        if (deck%get_word('run', 'analysis') /= 'dynamic') then
            call make_input_error(error, deck%file, deck%line('run', 'analysis'), 'analysis', &
                                  'a coupled run (continuum, particles and [coupling]) is a time integration: '// &
                                  'set analysis = dynamic')
            return
        end if
        scheme = deck%get_word('time', 'scheme')
        ok = scheme == 'average_acceleration'
        if (scheme == 'newmark') ok = abs(deck%get_real('time', 'beta') - 0.25_wp) <= 0 .and. &
                                      abs(deck%get_real('time', 'gamma') - 0.5_wp) <= 0
        if (.not. ok) call make_input_error(error, deck%file, deck%line('time', 'scheme'), 'scheme', &
                                            'coupled runs need scheme = average_acceleration (beta = 0.25, '// &
                                            'gamma = 0.5); '//scheme_why)
    end subroutine check_coupled2d_scheme

    !> Build and check the coupling of a deck with [continuum], [particles] and [coupling].
    subroutine build_coupling2d_config(deck, model, particle_gravity, x, y, setup, error)
        !> Deck read with the MULTICOR schema.
        type(deck_t), intent(in) :: deck
        !> The continuum (its mesh and materials: the thickness under the regions).
        type(continuum_model_t), intent(in) :: model
        !> Gravity of [particles] [m/s^2].
        real(wp), intent(in) :: particle_gravity(2)
        !> Centres of the disks [m] (n_disks each): every region must hold one.
        real(wp), intent(in) :: x(:), y(:)
        !> The coupling.
        type(coupled2d_setup_t), intent(out) :: setup
        !> Error naming file, line and keyword, if any.
        type(error_t), allocatable, intent(out) :: error
        type(deck_entry_t), allocatable :: regions(:)
        type(overlap2d_t), allocatable :: parts(:)
        type(weight_config_t) :: weight
        character(len=*), parameter :: beam_only(3) = [character(len=10) :: 'overlap', 'max_offset', 'coupled']
        real(wp) :: gravity(2), theta
        character(len=:), allocatable :: message
        integer :: j, k
        allocate (setup%warnings(0))
        call check_schemes(error)
        if (allocated(error)) return
        do k = 1, size(beam_only)
            if (.not. deck%has('coupling', trim(beam_only(k)))) cycle
            call make_input_error(error, deck%file, deck%line('coupling', trim(beam_only(k))), trim(beam_only(k)), &
                                  'applies to a beam coupled to particles; a [continuum] coupling takes its overlap '// &
                                  'from region lines and couples every disk whose centre lies in a region')
            return
        end do
        gravity = [deck%get_real('continuum', 'gravity', 'gx'), deck%get_real('continuum', 'gravity', 'gy')]
        if (any(gravity /= particle_gravity)) then
            k = deck%line('continuum', 'gravity')
            if (k == 0) k = deck%line('particles', 'gravity')
            call make_input_error(error, deck%file, k, 'gravity', 'coupled runs need the same gravity in '// &
                                  '[continuum] and [particles] (the two models share the weight in the overlap): '// &
                                  '[continuum] gravity = '//to_str(gravity(1))//' '//to_str(gravity(2))// &
                                  ', [particles] gravity = '//to_str(particle_gravity(1))//' '// &
                                  to_str(particle_gravity(2)))
            return
        end if
        if (.not. deck%has('coupling', 'thickness')) then
            call make_input_error(error, deck%file, first_line(), 'thickness', '[coupling] needs thickness = '// &
                                  'the out-of-plane depth of the disks [m] (usually the continuum''s thickness)')
            return
        end if
        regions = deck%records('coupling', 'region')
        if (size(regions) == 0) then
            call make_input_error(error, deck%file, first_line(), 'region', '[coupling] of a [continuum] needs '// &
                                  'at least one region = box xmin xmax ymin ymax fe_side particle_side (or polygon ...)')
            return
        end if
        setup%region_line = regions(1)%line
        weight%shape = deck%get_word('coupling', 'weight')
        weight%alpha_min = deck%get_real('coupling', 'alpha_min')
        weight%constant = deck%get_real('coupling', 'constant')
        ! (checked here to name the constant's line, the library would name the region's; the
        ! default 0.5 always lies in the range)
        if (weight%shape == 'constant' .and. weight%alpha_min > 0 .and. weight%alpha_min < 0.5_wp .and. &
            .not. (weight%constant >= weight%alpha_min .and. weight%constant <= 1 - weight%alpha_min)) then
            call make_input_error(error, deck%file, deck%line('coupling', 'constant'), 'constant', 'constant = '// &
                                  to_str(weight%constant)//' must lie in [alpha_min, 1 - alpha_min] = ['// &
                                  to_str(weight%alpha_min)//', '//to_str(1 - weight%alpha_min)//'] ([coupling] '// &
                                  'alpha_min, default 1e-3): a coupled disk or element with a weight nearer 0 or 1 '// &
                                  'has almost no mass on one side and makes the multiplier system ill-conditioned; '// &
                                  'raise constant or lower alpha_min')
            return
        end if
        allocate (parts(size(regions)))
        do k = 1, size(regions)
            call make_region(regions(k), parts(k), error)
            if (allocated(error)) return
            ! A region without a disk weights its part of the continuum by alpha < 1 with no
            ! particles to carry the rest: that part would lose stiffness and mass, silently.
            if (.not. any([(parts(k)%contains(x(j), y(j)), j=1, size(x))])) then
                call make_input_error(error, deck%file, regions(k)%line, 'region', 'no disk centre lies in this '// &
                                      'region: the continuum there would be weighted by alpha with no particles '// &
                                      'to carry the rest of its stiffness and mass; remove the region or put disks '// &
                                      'in it')
                return
            end if
            ! A point in two regions would be weighted twice (the Arlequin partition of unity).
            do j = 1, k - 1
                if (regions_overlap(parts(j), parts(k))) then
                    call make_input_error(error, deck%file, regions(k)%line, 'region', 'this region and '// &
                                          'the region of line '//to_str(regions(j)%line)//' overlap: the '// &
                                          'Arlequin weights of their common area would count twice; make the '// &
                                          'regions disjoint (they may share an edge)')
                    return
                end if
            end do
        end do
        if (size(parts) == 1) then
            allocate (setup%config%region, source=parts(1))
        else
            allocate (setup%config%region, source=overlap_set_t(parts))
        end if
        associate (c => setup%config)
            c%thickness = deck%get_real('coupling', 'thickness')
            c%memory_limit = available_memory()
            c%rotation_row = deck%get_word('coupling', 'rotation') == 'on'
            c%multipliers = merge(multipliers_nodes, multipliers_particles, &
                                  deck%get_word('coupling', 'multipliers') == 'nodes')
            c%pairing = merge(pairing_h1, pairing_l2, deck%get_word('coupling', 'pairing') == 'h1')
            c%h1_length = deck%get_real('coupling', 'h1_length')
            call make_mass_scheme(deck%get_word('continuum', 'mass'), c%mass_scheme, error)
            if (allocated(error)) return
            c%rayleigh = [deck%get_real('continuum', 'rayleigh', 'a0'), deck%get_real('continuum', 'rayleigh', 'a1')]
            c%gravity = gravity
        end associate
        call check_thickness(setup%config%thickness)

    contains

        !> A warning when thickness differs from the thickness of a material of the elements
        !> under the regions (centroid in a region; for regions narrower than the elements, a
        !> node in a region): the disks' masses and forces scale with thickness, the continuum's
        !> with its own, so that the two models of the overlap would stand for different amounts
        !> of one body, and their weighted masses would not add up to its mass.
        subroutine check_thickness(thickness)
            real(wp), intent(in) :: thickness
            type(deck_entry_t), allocatable :: materials(:)
            real(wp), allocatable :: xe(:, :)
            logical, allocatable :: under(:)
            integer :: e, m, i, n_elements
            n_elements = model%mesh%element_count()
            allocate (under(n_elements))
            do e = 1, n_elements
                xe = model%mesh%element_coordinates(e)
                under(e) = in_regions(sum(xe(1, :))/size(xe, 2), sum(xe(2, :))/size(xe, 2))
            end do
            if (.not. any(under)) then
                do e = 1, n_elements
                    xe = model%mesh%element_coordinates(e)
                    under(e) = any([(in_regions(xe(1, i), xe(2, i)), i=1, size(xe, 2))])
                end do
            end if
            materials = deck%records('continuum', 'material')
            do m = 1, size(model%materials)
                if (.not. any(under .and. model%element_material == m)) cycle
                associate (t => model%materials(m)%thickness)
                    if (abs(t - thickness) <= relative_roundoff*max(t, thickness)) cycle
                    message = 'warning: '//deck%file//':'//to_str(deck%line('coupling', 'thickness'))// &
                              ': [coupling] thickness = '//to_str(thickness)//' m differs from the thickness '// &
                              to_str(t)//' m of the continuum''s material under the region'
                    if (m <= size(materials)) message = message//' ([continuum] material, line '// &
                                                        to_str(materials(m)%line)//')'
                    message = message//': the disks'' masses and forces scale with the one, the '// &
                              'continuum''s with the other, so that in the overlap the two models stand for '// &
                              'different amounts of the same body; set thickness = '//to_str(t)
                end associate
                setup%warnings = [setup%warnings, string_t(message)]
            end do
        end subroutine check_thickness

        !> Whether a point lies in a region.
        logical function in_regions(px, py)
            real(wp), intent(in) :: px, py
            integer :: r
            in_regions = any([(parts(r)%contains(px, py), r=1, size(parts))])
        end function in_regions

        !> The analysis and the scheme (check_coupled2d_scheme), and theta.
        subroutine check_schemes(error)
            type(error_t), allocatable, intent(out) :: error
            call check_coupled2d_scheme(deck, error)
            if (allocated(error)) return
            theta = deck%get_real('time', 'theta')
            if (abs(theta - 0.5_wp) > 0) then
                message = 'warning: '//deck%file//':'//to_str(deck%line('time', 'theta'))//': [time] theta = '// &
                          to_str(theta)//' in a coupled run: the energy balance does not close; '//scheme_why
                setup%warnings = [setup%warnings, string_t(message)]
            end if
        end subroutine check_schemes

        !> One region line.
        subroutine make_region(e, region, error)
            type(deck_entry_t), intent(in) :: e
            type(overlap2d_t), intent(out) :: region
            type(error_t), allocatable, intent(out) :: error
            character(len=:), allocatable :: message
            real(wp), allocatable :: v(:)
            integer :: i, nv, tags(2)
            if (e%word('kind') == 'box') then
                call make_box_overlap(e%real('xmin'), e%real('xmax'), e%real('ymin'), e%real('ymax'), &
                                      side(e%word('fe_side')), side(e%word('particle_side')), weight, region, error)
            else
                v = e%reals_from('a')
                nv = size(v)/2 - 1
                do i = 1, 2
                    tags(i) = nint(v(i))
                    if (v(i) == tags(i) .and. tags(i) >= 0 .and. tags(i) <= nv) cycle
                    call make_input_error(error, deck%file, e%line, 'region', 'polygon: the '// &
                                          trim(merge('FE-side      ', 'particle-side', i == 1))//' edge number '// &
                                          to_str(v(i))//' must be an integer in 0..'//to_str(nv)// &
                                          ' (edge k joins vertex k to k + 1; 0: none)')
                    return
                end do
                call make_polygon_overlap(reshape(v(3:), [2, nv]), pack([tags(1)], tags(1) > 0), &
                                          pack([tags(2)], tags(2) > 0), weight, region, error)
            end if
            if (allocated(error)) then
                message = error%message
                call make_input_error(error, deck%file, e%line, 'region', message)
            end if
        end subroutine make_region

        !> Side name for the library ('' for none).
        pure function side(word) result(name)
            character(len=*), intent(in) :: word
            character(len=:), allocatable :: name
            name = trim(word)
            if (name == 'none') name = ''
        end function side

        !> Line of the first [coupling] entry.
        integer function first_line()
            integer :: i
            first_line = 0
            do i = 1, size(deck%entries)
                if (deck%entries(i)%section /= 'coupling' .or. deck%entries(i)%line == 0) cycle
                first_line = deck%entries(i)%line
                return
            end do
        end function first_line
    end subroutine build_coupling2d_config
end module driver_config_coupling2d
