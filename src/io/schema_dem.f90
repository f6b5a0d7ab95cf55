!> Deck sections of the discrete elements (rigid disks, Contact Dynamics), declared as data:
!> [particles] (materials, disks and their generators, gravity, conditions), [walls],
!> [contacts] (contact laws per pair of materials, alert distance) and [solver] (non-linear
!> Gauss-Seidel settings). Machinery and field builders: io_deck_schema. Cross-line checks
!> (material ids, selections against the number of disks, overlaps) are in driver_config_dem.
module io_schema_dem
    use core_kinds, only: wp
    use io_deck_schema, only: schema_t, int_field, real_field, positive, word_field, &
                              selection_field, tail, when, unless
    implicit none
    private

    !> Words naming a DOF: the [beam] and [particles] vocabularies are both accepted
    !> (u = x, w = y, theta = rot).
    character(len=*), parameter :: dof_words = 'x y rot u w theta'
    !> Largest friction coefficient of a law or a bond. The bi-potential local solver weighs
    !> the normal velocity against mu |u_t| (De Saxce's velocity): an oblique impact on a wall
    !> is exact up to mu = 1e4 and from 2e4 the disk sinks into the wall (steps unconverged),
    !> from 1e16 the contact acts no more, silently. 1000 keeps a factor 10 of margin and
    !> already sticks wherever a measured friction coefficient (at most a few) does.
    real(wp), parameter :: max_friction = 1000.0_wp
    public :: add_particles, add_walls, add_contacts, add_solver

contains

    !> [particles]: materials, disks, generators, gravity, conditions.
    subroutine add_particles(s)
        !> Schema to extend.
        type(schema_t), intent(inout) :: s
        call s%add_section('particles', 'Rigid disks (discrete elements), per unit thickness: '// &
                           'materials, disks and generators, gravity, conditions. Disks are numbered 1..N in '// &
                           'the order the deck creates them; conditions select them by number (`5`), range '// &
                           '(`1:10`, `11:last`), `last` (= N) or `all`.')
        call s%add_keyword('particles', 'material', [int_field('id', lower=1), &
                                                     positive('density', 'kg/m^3')], &
                           'A disk material: mass m = density pi R^2 and inertia I = m R^2 / 2 per unit '// &
                           'thickness; contact laws between materials are in [contacts].', repeatable=.true.)
        call s%add_keyword('particles', 'disk', [real_field('x', 'm'), real_field('y', 'm'), &
                                                 positive('radius', 'm'), int_field('material', lower=1)], &
                           'One disk centred at (x, y).', repeatable=.true.)
        call s%add_keyword('particles', 'row', [int_field('n', lower=1), real_field('x0', 'm'), &
                                                real_field('y0', 'm'), positive('radius', 'm'), int_field('material', lower=1)], &
                           'Generator: n disks in a straight chain from the centre (x0, y0) in the direction '// &
                           'angle_deg from the x axis (default 0), centres 2 radius + gap apart (default '// &
                           'gap 0: touching).', &
                           tails=[tail([real_field('gap', 'm', lower=0.0_wp), real_field('angle_deg', 'deg')], &
                                       0, 2)], repeatable=.true.)
        call s%add_keyword('particles', 'square_lattice', [int_field('nx', lower=1), &
                                                           int_field('ny', lower=1), real_field('x0', 'm'), real_field('y0', 'm'), &
                                                           positive('radius', 'm'), int_field('material', lower=1)], &
                           'Generator: ny rows of nx disks on a square lattice of pitch 2 radius + gap '// &
                           '(default gap 0: touching), lower-left centre (x0, y0), numbered row by row.', &
                           tails=[tail([real_field('gap', 'm', lower=0.0_wp)], 0, 1)], repeatable=.true.)
        call s%add_keyword('particles', 'hex_lattice', [int_field('nx', lower=1), &
                                                        int_field('ny', lower=1), real_field('x0', 'm'), real_field('y0', 'm'), &
                                                        positive('radius', 'm'), int_field('material', lower=1)], &
                           'Generator: ny rows of nx disks on a hexagonal lattice of pitch 2 radius + gap '// &
                           '(default gap 0: touching), rows sqrt(3)/2 pitch apart, every other row shifted by '// &
                           'half a pitch, lower-left centre (x0, y0), numbered row by row.', &
                           tails=[tail([real_field('gap', 'm', lower=0.0_wp)], 0, 1)], repeatable=.true.)
        call s%add_keyword('particles', 'deposit', [int_field('n', lower=1), &
                                                    real_field('xmin', 'm'), real_field('xmax', 'm'), real_field('ymin', 'm'), &
                                                    positive('rmin', 'm'), positive('rmax', 'm'), int_field('material', lower=1), &
                                                    int_field('seed')], &
                           'Generator: n disks of radii uniform in [rmin, rmax], loose in the box x in '// &
                           '[xmin, xmax], y >= ymin: one per site of a square grid of pitch 2 rmax '// &
                           '(1 + gap_ratio) (default gap_ratio 0.1), filled row by row from the bottom, '// &
                           'shifted at random in its site without overlap; the same seed gives the same '// &
                           'deposit.', tails=[tail([real_field('gap_ratio', '', lower=0.0_wp)], 0, 1)], &
                           repeatable=.true.)
        call s%add_keyword('particles', 'gravity', [real_field('gx', 'm/s^2'), &
                                                    real_field('gy', 'm/s^2')], &
                           'Gravity acceleration (the default is none; write gravity = 0 -9.81 for the usual '// &
                           'one).', default='0 0')
        call s%add_keyword('particles', 'fix', [selection_field('particles')], &
                           'Hold DOFs of the selected disks at zero velocity: x, y, rot (rotation), or all; u, w '// &
                           'and theta are the same DOFs under the names [beam] uses.', &
                           tails=[tail([word_field('dof', 'x y rot all u w theta')], 1, 3, cyclic=.true.)], &
                           repeatable=.true.)
        call s%add_keyword('particles', 'velocity', [selection_field('particles'), &
                                                     word_field('dof', dof_words), real_field('value', 'm/s or rad/s')], &
                           'Impose the velocity of one DOF of the selected disks: value times a time '// &
                           'function (none: constant 1).', &
                           tails=[tail([int_field('function', lower=1)], 0, 1)], repeatable=.true.)
        call s%add_keyword('particles', 'force', [selection_field('particles'), &
                                                  word_field('dof', dof_words), real_field('value', 'N/m or N')], &
                           'Force per unit thickness (x, y) or torque (rot) on each selected disk, times a '// &
                           'time function (none: constant 1); forces on the same DOF add up.', &
                           tails=[tail([int_field('function', lower=1)], 0, 1)], repeatable=.true.)
        call s%add_hint('particles', 'moment', "a torque on disks is a force on their rotation: "// &
                        "'force = <disks> rot <value> [function]'")
        call s%add_hint('particles', 'torque', "a torque on disks is a force on their rotation: "// &
                        "'force = <disks> rot <value> [function]'")
        call s%add_keyword('particles', 'initial_velocity', [selection_field('particles'), &
                                                             word_field('dof', dof_words), real_field('value', 'm/s or rad/s')], &
                           'Velocity at t = 0 of one free DOF of the selected disks (the others start at '// &
                           'rest); a later record overrides an earlier one.', repeatable=.true.)
        call s%add_keyword('particles', 'initial_rigid', [selection_field('particles'), &
                                                          real_field('vx', 'm/s'), real_field('vy', 'm/s'), &
                                                          real_field('omega', 'rad/s'), &
                                                          real_field('xc', 'm'), real_field('yc', 'm')], &
                           'Velocity at t = 0 of a rigid motion of the selected disks: translation (vx, vy) '// &
                           'plus rotation omega about (xc, yc), so that a disk centred at (x, y) gets (vx - '// &
                           'omega (y - yc), vy + omega (x - xc)) and the rotation rate omega; a DOF that is '// &
                           'fixed or imposed must get zero from it. Records apply in deck order with '// &
                           'initial_velocity.', repeatable=.true.)
    end subroutine add_particles

    !> [walls]: straight walls, fixed or driven.
    subroutine add_walls(s)
        !> Schema to extend.
        type(schema_t), intent(inout) :: s
        call s%add_section('walls', 'Rigid straight walls (segments of zero thickness, touched '// &
                           'on either side), fixed or driven in translation; numbered 1..n in deck order.')
        call s%add_keyword('walls', 'wall', [real_field('x1', 'm'), real_field('y1', 'm'), &
                                             real_field('x2', 'm'), real_field('y2', 'm')], &
                           'A wall from (x1, y1) to (x2, y2), of a [particles] material (default: the first '// &
                           'one declared), moving at the velocity (vx, vy) times a time function (default '// &
                           'fixed; function none: constant 1). Write 4, 5, 7 or 8 values.', &
                           tails=[tail([int_field('material', lower=1), real_field('vx', 'm/s'), &
                                        real_field('vy', 'm/s'), int_field('function', lower=1)], 0, 4)], repeatable=.true.)
    end subroutine add_walls

    !> [contacts]: contact laws and detection.
    subroutine add_contacts(s)
        !> Schema to extend.
        type(schema_t), intent(inout) :: s
        call s%add_section('contacts', 'Contact laws between materials (Signorini, Coulomb '// &
                           'friction, Newton restitution, cohesion) and contact detection. A pair of '// &
                           'materials without a law is frictionless, perfectly plastic (e = 0), not cohesive; '// &
                           'in a deck that gives laws to other pairs, walls of a material without a law with '// &
                           'any material of the disks, or disks of one without a law with any material of the '// &
                           'walls, are warned about.')
        call s%add_keyword('contacts', 'law', [int_field('material1', lower=1), &
                                               int_field('material2', lower=1), &
                                               real_field('mu', '', lower=0.0_wp, upper=max_friction), &
                                               real_field('restitution', '', lower=0.0_wp, upper=1.0_wp), &
                                               real_field('cohesion', 'Pa', lower=0.0_wp)], &
                           'Law of the contacts between two materials (either order): friction coefficient '// &
                           '(at most 1000, which sticks wherever a real contact does: the local solver is exact '// &
                           'to 1e4 and loses the normal direction beyond, letting disks sink), '// &
                           'restitution coefficient (with friction and e close to 1 an oblique impact can '// &
                           'gain energy, Kane''s paradox of Newton''s law; the run warns, doc/theory.md 2.4), '// &
                           'cohesion stress sigma_cohe (the bond holds a tension '// &
                           'sigma_cohe times the mean radius of the pair per unit thickness; bonds form '// &
                           'between touching disks at t = 0 and break for good once a bound of their law is '// &
                           'reached), and optionally the rolling resistance length e_r (default 0: none; '// &
                           '|M| <= e_r r_n; a warning when it exceeds the radius of the largest disk of the '// &
                           'two materials). Without a `bond` record the bonds of the pair keep mu and e_r: '// &
                           'with both 0 they hold opening only (a hinge).', &
                           tails=[tail([real_field('rolling', 'm', lower=0.0_wp)], 0, 1)], repeatable=.true.)
        call s%add_keyword('contacts', 'bond', [int_field('material1', lower=1), &
                                                int_field('material2', lower=1), &
                                                real_field('mu_b', '', lower=0.0_wp, upper=max_friction)], &
                           'Bounds of the bonds between two materials (either order; the pair needs a law '// &
                           'with cohesion): an intact bond holds |r_t| <= mu_b (r_n + r_cohe) and |M| <= e_b '// &
                           '(r_n + r_cohe), mu_b at most 1000 as mu, e_b in m (default: half the mean radius of '// &
                           'the pair, the moment '// &
                           'capacity of a rigid-plastic bond section, doc/theory.md). A bond that reaches a '// &
                           'bound breaks for good (tension, shear or moment) and the contact follows `law`.', &
                           tails=[tail([real_field('e_b', 'm', lower=0.0_wp)], 0, 1)], repeatable=.true.)
        call s%add_keyword('contacts', 'alert', [real_field('alert', 'm', lower=0.0_wp)], &
                           'Alert distance: pairs closer than this are candidate contacts of the step '// &
                           '(default 0.25 times the mean disk radius); it must exceed the distance a disk '// &
                           'travels in one step (a warning says when it does not); 0 is warned about: a '// &
                           'contact is then seen only once its disks touch.')
    end subroutine add_contacts

    !> [solver]: non-linear Gauss-Seidel settings.
    subroutine add_solver(s)
        !> Schema to extend.
        type(schema_t), intent(inout) :: s
        call s%add_section('solver', 'Contact solver of the particles: non-linear Gauss-Seidel '// &
                           'sweeps over the contacts with the bi-potential local solver, at every time step; '// &
                           'with `method = block` the intact bonds are solved directly as one block.')
        call s%add_keyword('solver', 'method', [word_field('method', 'block nlgs coarse')], &
                           'Global strategy. `nlgs`: Gauss-Seidel sweeps over every contact. `block`: the '// &
                           'intact bonds (with the coupling rows) are solved exactly as one sparse block '// &
                           '(CHOLMOD), alternating with sweeps over the other contacts (block Gauss-Seidel); a '// &
                           'bond whose reaction leaves its cone is released and the step solved again, so the '// &
                           'bonds break as with `nlgs`. A step without intact bonds (none in the deck, or all '// &
                           'broken) is the same sweeps with both, bit for bit, converged or not. `coarse`: the '// &
                           'sweeps of `nlgs` with a coarse correction every `coarse_every` sweeps, which scales '// &
                           'the reactions of aggregates of `coarse_size` consecutive contacts at once (for tall '// &
                           'packings away from rest and deposits, doc/performance.md; it changes nothing at a '// &
                           'solution, and a step stops correcting once the error at a correction is larger '// &
                           'than at the previous one; not with the Arlequin coupling rows: a coupled run '// &
                           'sweeps as with `nlgs`, and says so in a warning; its aggregates leave bonds out). '// &
                           'With `[contacts] bond` records, `nlgs` and `coarse` sweep the bonds one contact at '// &
                           'a time: along a bonded chain the sweeps converge slowly, and their stopping test can '// &
                           'be met far from the solution (a warning says so above a tolerance of 1e-8). Every '// &
                           'unilateral or frictional contact uses the bi-potential local solver in all three.', &
                           default='block')
        call s%add_keyword('solver', 'tolerance', [real_field('tolerance', '', lower=0.0_wp, upper=1.0_wp, &
                                                              lower_strict=.true., upper_strict=.true.)], &
                           'Convergence of the sweeps: change of the local velocities over a sweep relative '// &
                           'to W r (quadratic mean over the active contacts). A convergence study that refines '// &
                           'the model (mesh, particle size, time step) needs a tolerance well below the errors '// &
                           'it measures (1e-10 or less): at the default the solver''s error hides the finest '// &
                           'levels (a coupled beam refined to R = 0.625 mm needed 1e-12).', default='1.666e-4')
        call s%add_keyword('solver', 'max_sweeps', [int_field('max_sweeps', lower=1)], &
                           'Largest number of sweeps per step (with `method = block`: block iterations, each a '// &
                           'direct solve of the bonds and a sweep over the other contacts, over all the passes '// &
                           'of the step: a bond released by the check of the bonds'' cones starts a new pass '// &
                           'with the iterations left, and a step out of them with a bond still outside its cone '// &
                           'ends unconverged, its error at least the bond''s relative excess over its bound; a '// &
                           'step whose block of intact bonds created energy is solved again by plain sweeps from zero '// &
                           'reactions, which take up to max_sweeps more, counted too: doc/theory.md 7.10); a '// &
                           'step that reaches it without converging is reported (warning) and counted. The cap '// &
                           'is over all the solves of the step: a step solved again because the rule of '// &
                           'activation let in contacts that the solve shut ([time] contact_scheme = multicor, '// &
                           'doc/theory.md 2.4) has the sweeps the solves before left.', default='1000')
        call s%add_keyword('solver', 'local_tolerance', [real_field('local_tolerance', '', lower=0.0_wp, &
                                                                    upper=1.0_wp, lower_strict=.true., &
                                                                    upper_strict=.true.)], &
                           'Relative tolerance of the local prediction-correction iterations of one contact.', &
                           default='1e-10')
        call s%add_keyword('solver', 'local_iterations', [int_field('local_iterations', lower=1)], &
                           'Largest number of local prediction-correction iterations per contact visit (a '// &
                           'contact with a moment length, rolling resistance or a bond with e_b > 0, that '// &
                           'reaches it is then solved exactly, branch by branch, doc/theory.md 7.4; another '// &
                           'contact stops at the cap).', &
                           default='8')
        call s%add_keyword('solver', 'criterion', [word_field('criterion', 'lmgc90 siconos')], &
                           'Which error stops the sweeps: lmgc90 (the change of W r over a sweep, see '// &
                           'tolerance) or siconos (the norm of r - P_K(r - u_hat) over the largest norm of q, r and '// &
                           'u, with u = W r + q computed in full, doc/theory.md 4.5). Both are stored per step in '// &
                           'the results.', &
                           default='lmgc90')
        call s%add_keyword('solver', 'relaxation', [real_field('relaxation', '', lower=0.0_wp, upper=2.0_wp, &
                                                               lower_strict=.true., upper_strict=.true.)], &
                           'Over-relaxation factor omega of the sweeps: each contact takes P_K(r + omega '// &
                           '(r_local - r)). Every `check_every` sweeps the error is compared with the one '// &
                           'before; omega falls back to 1 for the rest of the step when it rose. An omega '// &
                           'past the best one can slow the sweeps while the error still falls (a column of '// &
                           '20 disks: 5568 sweeps at 1.9 against 4248 at 1, 2128 at 1.5): try it on the '// &
                           'deck first.', default='1')
        call s%add_keyword('solver', 'anderson', [int_field('anderson', lower=0, upper=20)], &
                           'Anderson acceleration of the sweeps: the number of previous sweeps mixed; 0: '// &
                           'plain sweeps (the default, 5, is the fastest measured on deposits and tall '// &
                           'packings, doc/performance.md). The '// &
                           'accelerated sweeps run in the fixed contact order; the history restarts when the '// &
                           'change over a sweep grows. With the Arlequin coupling rows too (their multipliers '// &
                           'follow the mixed reactions exactly). With method = block, the block is solved '// &
                           'again for the mixed reactions (the bonds it released are mixed too). Not used in '// &
                           'a step whose intact bonds are all swept (method = nlgs).', &
                           default='5')
        call s%add_keyword('solver', 'anderson_after', [int_field('anderson_after', lower=0)], &
                           'With `anderson` > 0: plain sweeps before the Anderson steps start. A step that '// &
                           'converges within them is not accelerated: near rest a plain sweep is cheaper and '// &
                           'a few suffice (doc/performance.md).', default='10', &
                           effective_when=unless('solver', 'anderson', '0'))
        call s%add_keyword('solver', 'anderson_sweeps', [int_field('anderson_sweeps', lower=1)], &
                           'With `anderson` > 0: sweeps per Anderson step (the map accelerated is that '// &
                           'many forward sweeps). An Anderson step costs about one sweep; over 2 sweeps its '// &
                           'cost per sweep is half, for about as many sweeps (doc/performance.md). 1 mixes '// &
                           'after every sweep.', default='2', &
                           effective_when=unless('solver', 'anderson', '0'))
        call s%add_keyword('solver', 'sweep_order', [word_field('sweep_order', 'alternating forward')], &
                           'Order of the plain sweeps: `alternating` (forward, then backward through the '// &
                           'contact list, in turn: symmetric Gauss-Seidel) or `forward` (every sweep in the '// &
                           'contact order, bottom-up in a packing whose disks are numbered by layers). '// &
                           'Forward needs 1.4 to 1.9 times fewer sweeps on gravity deposits '// &
                           '(doc/performance.md); alternating carries information both ways along bonded '// &
                           'chains and coupled interfaces, which need it. Anderson steps always run forward.', &
                           default='alternating')
        call s%add_keyword('solver', 'cold_start', [word_field('cold_start', 'zero hydrostatic')], &
                           'Start of a step in which no contact carries a reaction yet (the first step of '// &
                           'a packing built at rest): `zero` reactions, or the `hydrostatic` estimate, the '// &
                           'weight carried down the contact network from the top and split at each disk over '// &
                           'its supports within their friction cones (doc/theory.md 4.7). On tall packings '// &
                           'it cuts the sweeps of that step 2 to 6 times; on hexagonal lattices the steps that '// &
                           'follow can need several times more (doc/performance.md). Not used with the Arlequin '// &
                           'coupling rows (a warning), nor in a step where method = block solves intact bonds directly.', &
                           default='zero')
        call s%add_keyword('solver', 'coarse_every', [int_field('coarse_every', lower=1)], &
                           'With `method = coarse`: sweeps between two coarse corrections (one more before '// &
                           'the first sweep).', default='10', &
                           effective_when=when('solver', 'method', 'coarse'))
        call s%add_keyword('solver', 'coarse_size', [int_field('coarse_size', lower=1)], &
                           'With `method = coarse`: contacts per aggregate, consecutive in the contact list '// &
                           '(ordered by disk: disks numbered by layers give horizontal slabs); larger when '// &
                           'there would be more than 2000 aggregates.', default='400', &
                           effective_when=when('solver', 'method', 'coarse'))
        call s%add_keyword('solver', 'check_every', [int_field('check_every', lower=1)], &
                           'Period in sweeps of the safeguard of the over-relaxation.', default='10', &
                           effective_when=unless('solver', 'relaxation', '1'))
        call s%add_keyword('solver', 'fclib_step', [int_field('fclib_step', lower=1)], &
                           'Write the local contact problem of this step (W, q, mu, cohesion, rolling '// &
                           'lengths and the solution found) in FCLIB''s HDF5 format to <output>_fclib_<step>.h5 '// &
                           '(doc/theory.md, "Siconos error"). In a coupled run: the problem the contacts see, '// &
                           'the coupling rows condensed (W dense among the contacts on coupled disks). '// &
                           'A step without active contacts is not written (FCLIB refuses an empty problem): a '// &
                           'warning, as for a step after the end (which --check reports too). When a contact has a '// &
                           'moment (rolling resistance, a bond with a moment) the file has spacedim = 3: the '// &
                           'third component is the moment, with the cone of doc/theory.md 7.3, and a 3D Coulomb '// &
                           'solver of FCLIB reads another problem (a second tangent, a circular cone); the run '// &
                           'then says so. Default: none.')
    end subroutine add_solver
end module io_schema_dem
