!> Deck section of the 2D elastic continuum, declared as data: [continuum] (mesh, materials,
!> supports, prescribed displacements, loads, damping, initial velocity). Machinery and field
!> builders: io_deck_schema.
module io_schema_continuum
    use core_kinds, only: wp
    use io_deck_schema, only: schema_t, tail_spec_t, int_field, real_field, positive, word_field, name_field, tail, when, unless
    implicit none
    private
    public :: add_continuum

contains

    !> [continuum]: plane strain or plane stress linear elasticity on a Q4/T3 mesh.
    subroutine add_continuum(s)
        !> Schema to extend.
        type(schema_t), intent(inout) :: s
        type(tail_spec_t), allocatable :: tails(:)
        call s%add_section('continuum', &
                           '2D linear-elastic continuum (plane strain or plane stress, Q4 and T3 elements); '// &
                           'named node, element and edge sets come from the mesh.')
        tails = [tail([real_field('x0', 'm'), real_field('y0', 'm'), positive('lx', 'm'), positive('ly', 'm'), &
                       int_field('nx', lower=1), int_field('ny', lower=1), word_field('element', 'q4 t3')], &
                      7, 7, selected_by='rectangle'), &
                 tail([name_field('path')], 1, 1, selected_by='file')]
        call s%add_keyword('continuum', 'mesh', [word_field('kind', 'rectangle file')], &
                           'rectangle: [x0, x0 + lx] x [y0, y0 + ly] with nx x ny Q4 (or 2 nx ny T3), sets '// &
                           'left, right, bottom, top (nodes and edges) and all (nodes and elements); file: a '// &
                           'Gmsh 4.1 ASCII .msh (path relative to the deck''s folder, in double quotes if it holds '// &
                           'blanks), its physical groups as named sets.', &
                           selector=1, tails=tails)
        call s%add_keyword('continuum', 'material', [positive('young', 'Pa'), &
                                                     real_field('poisson', '', lower=-1.0_wp, upper=0.5_wp, &
                                                                lower_strict=.true., upper_strict=.true.), &
                                                     real_field('density', 'kg/m^3', lower=0.0_wp), &
                                                     positive('thickness', 'm'), &
                                                     word_field('hypothesis', 'plane_stress plane_strain')], &
                           'Isotropic elastic material of an element set (default all; later lines override '// &
                           'earlier ones on shared elements). In plane strain poisson <= 0.499999 (closer to '// &
                           '0.5 the stiffness cannot be factored in double precision).', &
                           tails=[tail([name_field('element_set')], 0, 1)], repeatable=.true.)
        call s%add_keyword('continuum', 'mass', [word_field('mass', 'consistent lumped')], &
                           'Mass matrix: consistent, or row-sum lumped (diagonal).', default='consistent', &
                           effective_when=unless('run', 'analysis', 'static'))
        call s%add_keyword('continuum', 'fix', [name_field('node_set')], &
                           'Zero displacement of the nodes of a set, components x and/or y (a dof given by '// &
                           'several fix or displacement records must get the same value and function from each).', &
                           tails=[tail([word_field('component', 'x y')], 1, 2)], repeatable=.true.)
        call s%add_keyword('continuum', 'displacement', [name_field('node_set'), &
                                                         word_field('component', 'x y'), real_field('value', 'm')], &
                           'Prescribed displacement of the nodes of a set: the value, or the value times a '// &
                           '[functions] time function (its rate and acceleration are the derivatives of the '// &
                           'function); a dof given twice must get the same value and function both times.', &
                           tails=[tail([int_field('function', lower=1)], 0, 1)], repeatable=.true.)
        call s%add_keyword('continuum', 'load', [name_field('node_set'), &
                                                 word_field('component', 'x y'), real_field('value', 'N')], &
                           'Force on every node of a set, times a [functions] time function (none: constant 1). '// &
                           'A load whose every force lands on a prescribed dof (fix, displacement) does nothing '// &
                           'and is an error.', &
                           tails=[tail([int_field('function', lower=1)], 0, 1)], repeatable=.true., &
                           effective_when=unless('run', 'analysis', 'modal'))
        call s%add_hint('continuum', 'force', "a force on nodes is 'load = <node_set> x|y <value> "// &
                        "[function]' (on an edge: 'traction')")
        call s%add_hint('continuum', 'moment', "the continuum's nodes have no rotation: apply a moment as "// &
                        "opposite forces on two node sets ('load') or as tractions on edges ('traction')")
        call s%add_hint('continuum', 'torque', "the continuum's nodes have no rotation: apply a moment as "// &
                        "opposite forces on two node sets ('load') or as tractions on edges ('traction')")
        call s%add_keyword('continuum', 'traction', [name_field('edge_set'), &
                                                     real_field('tx', 'Pa'), real_field('ty', 'Pa')], &
                           'Traction on the edges of a set: uniform, or parabolic (1.5 t (1 - s^2) with s from '// &
                           '-1 to 1 across the set along its longer extent, the same resultant as uniform t), '// &
                           'times a [functions] time function (none: constant 1; give the profile first). A '// &
                           'traction whose every force lands on a prescribed dof (a clamped edge) does nothing and '// &
                           'is an error.', &
                           tails=[tail([word_field('profile', 'uniform parabolic'), int_field('function', lower=1)], &
                                       0, 2)], repeatable=.true., effective_when=unless('run', 'analysis', 'modal'))
        call s%add_keyword('continuum', 'gravity', [real_field('gx', 'm/s^2'), real_field('gy', 'm/s^2')], &
                           'Acceleration of gravity (body force rho g).', default='0 0', &
                           effective_when=unless('run', 'analysis', 'modal'))
        call s%add_hint('continuum', 'damping', "damping is Rayleigh's: 'rayleigh = <a0> <a1>' (C = a0 M + a1 K)")
        call s%add_keyword('continuum', 'rayleigh', &
                           [real_field('a0', '1/s', lower=0.0_wp), real_field('a1', 's', lower=0.0_wp)], &
                           'Rayleigh damping C = a0 M + a1 K.', default='0 0', allowed_when=when('run', 'analysis', 'dynamic'))
        call s%add_keyword('continuum', 'initial_velocity', [real_field('vx', 'm/s'), real_field('vy', 'm/s')], &
                           'Initial velocity of the free nodes (dynamic analysis): (vx, vy) plus a rotation '// &
                           'omega (rad/s) about (xc, yc) (m), v = (vx - omega (y - yc), vy + omega (x - xc)); '// &
                           'the rotation is given whole (omega, xc and yc) or not at all.', &
                           tails=[tail([real_field('omega', 'rad/s'), real_field('xc', 'm'), real_field('yc', 'm')], &
                                       0, 3, cyclic=.true.)], default='0 0', allowed_when=when('run', 'analysis', 'dynamic'))
    end subroutine add_continuum
end module io_schema_continuum
