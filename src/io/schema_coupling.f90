!> Deck section of the Arlequin DEM-FEM coupling, declared as data: [coupling] (overlap
!> interval along the beam, weight function, out-of-plane thickness of the particles, which
!> disks are glued to the beam). Machinery and field builders: io_deck_schema. Checks across
!> sections (overlap inside the beam, coupled disks inside the overlap, time scheme) are in
!> driver_config_coupling.
module io_schema_coupling
    use core_kinds, only: wp
    use io_deck_schema, only: schema_t, real_field, positive, word_field, selection_field, &
                              tail, when, tail_spec_t
    implicit none
    private
    public :: add_coupling

contains

    !> [coupling]: the Arlequin overlap of a deck with both [beam] and [particles].
    subroutine add_coupling(s)
        !> Schema to extend.
        type(schema_t), intent(inout) :: s
        type(tail_spec_t), allocatable :: tails(:)
        call s%add_section('coupling', 'Arlequin coupling of a deck with [particles] and a [beam] or a '// &
                           '[continuum]: in the overlap the energies of both models are weighted by alpha '// &
                           '(FE) and 1 - alpha (disks), and Lagrange multipliers glue each coupled disk centre '// &
                           'to the FE model (doc/input.md, sections Coupled runs and Coupled continuum and disk '// &
                           'runs). '// &
                           'Coupled runs are dynamic, with [time] scheme = average_acceleration and '// &
                           'theta = 0.5.')
        call s%add_keyword('coupling', 'overlap', [real_field('s_fe', 'm', lower=0.0_wp), &
                                                   real_field('s_particle', 'm', lower=0.0_wp)], &
                           'Overlap interval, as abscissas along the beam from its first node: s_fe is the '// &
                           'end next to the FE-only zone (alpha = 1 before it), s_particle the end next to '// &
                           'the particle-only zone (alpha = 0 beyond it; the beam must end there). Required '// &
                           'in a beam coupled deck (a [continuum] takes region lines).')
        call s%add_keyword('coupling', 'weight', [word_field('weight', 'constant linear cubic')], &
                           'Shape of alpha across the overlap (xi = 0 at s_fe, 1 at s_particle): constant, '// &
                           'linear 1 - xi, or cubic 1 - 3 xi^2 + 2 xi^3 (zero slope at both ends).', &
                           default='cubic')
        call s%add_keyword('coupling', 'constant', [real_field('constant', '', lower=0.0_wp, &
                                                               upper=1.0_wp, lower_strict=.true., upper_strict=.true.)], &
                           'Value of alpha inside the overlap for weight = constant; it must lie in '// &
                           '[alpha_min, 1 - alpha_min] (see alpha_min).', default='0.5', &
                           allowed_when=when('coupling', 'weight', 'constant'))
        call s%add_keyword('coupling', 'alpha_min', [real_field('alpha_min', '', lower=1.0e-6_wp, &
                                                                upper=0.5_wp, upper_strict=.true.)], &
                           'Floor of the weight inside the overlap: alpha stays in [alpha_min, 1 - '// &
                           'alpha_min], so that no coupled disk gets a zero mass on one side (which would '// &
                           'make the multiplier system singular). Below 1e-6 the system is so badly '// &
                           'conditioned that its solve loses the bonds between coupled disks (a row '// &
                           'glued to a cantilever: 9e-7 off the closed form at 1e-6, 2e-5 with unconverged '// &
                           'steps at 1e-8, 1.7 % at 1e-12).', default='1e-3')
        call s%add_keyword('coupling', 'thickness', [positive('thickness', 'm')], &
                           'Out-of-plane depth of the disks (the particles are per unit thickness; the beam '// &
                           'is not): usually the width of the beam section (more than 100 times off the width '// &
                           'of the rectangle with its A and I: a warning), or the thickness of the '// &
                           '[continuum] material in the regions (another value: a warning). Required in a '// &
                           'coupled deck.')
        call s%add_keyword('coupling', 'rotation', [word_field('rotation', 'off on')], &
                           'Also glue the rotation of each coupled disk to the beam rotation theta.', &
                           default='off')
        call s%add_keyword('coupling', 'coupled', [word_field('coupled', '')], &
                           'Which disks are glued to the beam: auto (every disk whose centre lies in the '// &
                           'overlap, within max_offset of the axis), or selections of disks (`5`, `1:7`, '// &
                           '`last`, several allowed), each inside the overlap.', &
                           tails=[tail([selection_field('more')], 0, -1)], default='auto')
        call s%add_keyword('coupling', 'max_offset', [real_field('max_offset', 'm', &
                                                                 lower=0.0_wp)], &
                           'Couple only disks whose centre lies at most this far from the beam axis (with '// &
                           'coupled = auto; a listed disk farther away is an error); 0: any distance, with a '// &
                           'warning when a coupled disk lies farther than its radius plus the section''s '// &
                           'half-height sqrt(3 I / A) (it does not touch the beam). With '// &
                           'bonds between the layers and multipliers = particles, coupling several layers makes '// &
                           'the bonds and the coupling rows nearly redundant (a warning after the first step; '// &
                           'doc/theory.md 7.10): glue one layer, or put the multipliers on the nodes.', &
                           default='0')
        call s%add_keyword('coupling', 'multipliers', [word_field('multipliers', &
                                                                  'particles nodes')], &
                           'Space of the Lagrange multipliers: particles (one per coupled DOF: every '// &
                           'coupled disk centre follows the beam) or nodes (one per FE node carrying '// &
                           'coupled disks, x and y: only the projection of the disks'' residual on the '// &
                           'beam''s linear hat functions vanishes; a coarser mediator space).', &
                           default='particles')
        ! A 2D continuum coupled to disks ([continuum] with [particles]).
        tails = [tail([real_field('xmin', 'm'), real_field('xmax', 'm'), real_field('ymin', 'm'), &
                       real_field('ymax', 'm'), word_field('fe_side', 'bottom right top left none'), &
                       word_field('particle_side', 'bottom right top left none')], 6, 6, selected_by='box'), &
                 tail([real_field('a', ''), real_field('b', '')], 8, -1, cyclic=.true., selected_by='polygon')]
        call s%add_keyword('coupling', 'region', [word_field('kind', 'box polygon')], &
                           'Overlap region of a [continuum] coupled to [particles] (one line per region, the '// &
                           'regions disjoint: they may share edges, not areas; required there, not allowed with '// &
                           '[beam]). box: [xmin, xmax] x [ymin, ymax], '// &
                           'the side next to the FE-only zone and the side next to the particle-only zone '// &
                           '(none with weight = constant). polygon: fe_edge particle_edge x1 y1 x2 y2 x3 y3 ...: '// &
                           'the numbers of the FE-side and particle-side edges (edge k joins vertex k to k + 1, '// &
                           'the last to the first; 0: none), then at least 3 vertices, each given once (the '// &
                           'polygon closes itself; a repeated vertex, the first again at the end included, is '// &
                           'refused: its zero-length edge would shift the edge numbers). The polygon must be '// &
                           'simple, its vertices in order around it (either direction): edges that cross, '// &
                           'touch or fold back on each other are refused. alpha ramps from 1 - '// &
                           'alpha_min on the FE side to alpha_min on the particle side (weight, alpha_min). '// &
                           'Every region must hold at least one disk centre.', &
                           repeatable=.true., selector=1, tails=tails)
        call s%add_keyword('coupling', 'pairing', [word_field('pairing', 'l2 h1')], &
                           'Pairing of the mediator space of a [continuum] coupling (multipliers = nodes): l2 '// &
                           '(shape functions of the overlap nodes tested at the disk centres) or h1 (adds '// &
                           'h1_length^2 times the gradients; same constraint and motion, smoother multipliers).', &
                           default='l2', allowed_when=when('coupling', 'multipliers', 'nodes'))
        call s%add_keyword('coupling', 'h1_length', [real_field('h1_length', 'm', lower=0.0_wp)], &
                           'Length l of the H1 pairing (pairing = h1).', default='0', &
                           allowed_when=when('coupling', 'pairing', 'h1'))
    end subroutine add_coupling
end module io_schema_coupling
