!> Deck sections shared by every kind of run, declared as data: [run] (what to compute),
!> [functions] (time functions), [time] (time stepping, for beams and particles) and
!> [output] (what is stored). Machinery and field builders: io_deck_schema.
module io_schema_common
    use core_kinds, only: wp
    use io_deck_schema, only: schema_t, tail_spec_t, int_field, real_field, positive, &
                              word_field, text_field, tail, when
    implicit none
    private
    public :: add_run, add_functions, add_time, add_output

contains

    !> [run]: title and kind of analysis.
    subroutine add_run(s)
        !> Schema to extend.
        type(schema_t), intent(inout) :: s
        call s%add_section('run', 'What to compute.')
        call s%add_keyword('run', 'title', [text_field('title')], &
                           'Free text stored with the results.', default='')
        call s%add_keyword('run', 'analysis', [word_field('analysis', 'static modal dynamic')], &
                           'Kind of analysis: static equilibrium, natural modes, or time integration '// &
                           '(particles: dynamic only).', required=.true.)
    end subroutine add_run

    !> [functions]: time functions multiplying loads.
    subroutine add_functions(s)
        !> Schema to extend.
        type(schema_t), intent(inout) :: s
        type(tail_spec_t), allocatable :: tails(:)
        call s%add_section('functions', &
                           'Time functions f(t) that multiply loads, imposed velocities and wall velocities.')
        tails = [tail([real_field('c', '')], 1, 1, selected_by='constant'), &
                 tail([positive('t1', 's')], 1, 1, selected_by='ramp'), &
                 tail([real_field('t0', 's', lower=0.0_wp)], 1, 1, selected_by='step'), &
                 tail([real_field('t', 's'), real_field('f', '')], 4, -1, cyclic=.true., &
                      selected_by='table'), &
                 tail([positive('freq', 'Hz'), real_field('phase', 'rad')], 1, 2, &
                      selected_by='harmonic')]
        call s%add_keyword('functions', 'function', &
                           [int_field('id', lower=1), word_field('kind', 'constant ramp step table harmonic')], &
                           'constant: f = c; ramp: f = min(t/t1, 1); step: f = 0 before t0, 1 after; '// &
                           'table: linear in (t, f) pairs, t increasing, constant outside; '// &
                           'harmonic: f = sin(2 pi freq t + phase).', &
                           selector=2, tails=tails, repeatable=.true.)
    end subroutine add_functions

    !> [time]: time integration.
    subroutine add_time(s)
        !> Schema to extend.
        type(schema_t), intent(inout) :: s
        call s%add_section('time', 'Time integration (dynamic analysis).')
        call s%add_keyword('time', 'step', [positive('step', 's')], &
                           'Time step h.', required_when=when('run', 'analysis', 'dynamic'), &
                           allowed_when=when('run', 'analysis', 'dynamic'))
        call s%add_keyword('time', 'end', [positive('end', 's')], &
                           'End time (the run starts at t = 0).', required_when=when('run', 'analysis', 'dynamic'), &
                           allowed_when=when('run', 'analysis', 'dynamic'))
        call s%add_keyword('time', 'scheme', &
                           [word_field('scheme', 'average_acceleration newmark central_difference')], &
                           'Newmark family: average_acceleration (beta 1/4, gamma 1/2), newmark (beta and '// &
                           'gamma below), central_difference (beta 0, gamma 1/2, explicit).', &
                           default='average_acceleration', allowed_when=when('run', 'analysis', 'dynamic'))
        call s%add_keyword('time', 'beta', [real_field('beta', '', lower=0.0_wp, upper=0.5_wp)], &
                           'Newmark beta.', default='0.25', allowed_when=when('time', 'scheme', 'newmark'))
        call s%add_keyword('time', 'gamma', [real_field('gamma', '', lower=0.5_wp, upper=1.0_wp)], &
                           'Newmark gamma (> 1/2 adds numerical damping).', default='0.5', &
                           allowed_when=when('time', 'scheme', 'newmark'))
        call s%add_keyword('time', 'theta', [real_field('theta', '', lower=0.5_wp, upper=1.0_wp)], &
                           'Moreau-Jean theta of the particles: positions advance with (1 - theta) v(t) + '// &
                           'theta v(t + h); 1/2 conserves energy in free flight and elastic impacts, '// &
                           '1 is fully implicit (dissipative; with contact_scheme = multicor no contact overlaps, '// &
                           'below 1 a step takes one at most (1 - theta) h |u_n| in, doc/theory.md 2.4).', default='0.5', &
                           allowed_when=when('run', 'analysis', 'dynamic'))
        call s%add_keyword('time', 'contact_scheme', [word_field('contact_scheme', 'multicor siconos')], &
                           'How the contacts of the particles enter a step. multicor: detected on the '// &
                           'mid configuration q + (1 - theta) h v, active when the free motion closes '// &
                           'them or when they carried a load, a gap term for those still open; after the '// &
                           'solve, those left out that the others shut join it and the step is solved again '// &
                           '(doc/theory.md 2.3-2.4). siconos: the step of Siconos 4.4 (TimeStepping, '// &
                           'MoreauJeanOSI, one Newton iteration), to compare with it on the same discrete '// &
                           'problem: geometry at q + h v, active when the previous step''s gap plus h/2 '// &
                           'times its normal velocity is <= 0, no gap term (doc/theory.md 2.6).', &
                           default='multicor', allowed_when=when('run', 'analysis', 'dynamic'))
    end subroutine add_time

    !> [output]: what is stored and shown.
    subroutine add_output(s)
        !> Schema to extend.
        type(schema_t), intent(inout) :: s
        call s%add_section('output', 'Results and progress reports.')
        call s%add_keyword('output', 'interval', [int_field('interval', lower=1)], &
                           'Time steps between stored states.', default='1', &
                           effective_when=when('run', 'analysis', 'dynamic'))
        call s%add_keyword('output', 'progress', [real_field('progress', 's', lower=0.0_wp)], &
                           'Wall-clock seconds between progress lines (0 = none).', default='5')
        call s%add_keyword('output', 'contacts', [word_field('contacts', 'yes no')], &
                           'Store the contact network (pairs, normals, forces, statuses) with every stored '// &
                           'state of the particles.', default='yes')
        call s%add_keyword('output', 'checkpoint_interval', [int_field('checkpoint_interval', lower=0)], &
                           'Time steps between checkpoints (0 = none); a dynamic run also writes one at its end '// &
                           'and when a signal stops it (doc/output.md).', default='0', &
                           effective_when=when('run', 'analysis', 'dynamic'))
        call s%add_keyword('output', 'checkpoint_seconds', [real_field('checkpoint_seconds', 's', lower=0.0_wp)], &
                           'Wall-clock seconds between checkpoints (0 = none).', default='0', &
                           effective_when=when('run', 'analysis', 'dynamic'))
    end subroutine add_output
end module io_schema_common
