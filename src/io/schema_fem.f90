!> Deck sections of the beam finite elements, declared as data: [beam] (frame geometry,
!> sections, supports, loads), [modal] (natural modes) and [initial] (initial conditions of
!> the nodes). Machinery and field builders: io_deck_schema.
module io_schema_fem
    use core_kinds, only: wp
    use io_deck_schema, only: schema_t, int_field, real_field, positive, word_field, tail, when, unless
    implicit none
    private

    !> Words naming a DOF: the [beam] and [particles] vocabularies are both accepted
    !> (u = x, w = y, theta = rot).
    character(len=*), parameter :: dof_words = 'u w theta x y rot'
    public :: add_beam, add_modal, add_initial

contains

    !> [beam]: planar Euler-Bernoulli frame (sections, nodes, elements, supports, loads).
    subroutine add_beam(s)
        !> Schema to extend.
        type(schema_t), intent(inout) :: s
        call s%add_section('beam', &
                           'Planar Euler-Bernoulli frame: geometry, material, supports, loads.')
        call s%add_keyword('beam', 'mass', [word_field('mass', 'consistent lumped')], &
                           'Mass matrix: consistent, or lumped (HRZ, diagonal).', default='consistent', &
                           effective_when=unless('run', 'analysis', 'static'))
        call s%add_keyword('beam', 'section', [int_field('id', lower=1), &
                                               positive('young', 'Pa'), positive('density', 'kg/m^3'), positive('area', 'm^2'), &
                                               positive('inertia', 'm^4')], &
                           'Cross-section and material: Young modulus, density, area, second moment of area.', &
                           repeatable=.true.)
        call s%add_keyword('beam', 'node', &
                           [int_field('id', lower=1), real_field('x', 'm'), real_field('y', 'm')], &
                           'A node at (x, y).', repeatable=.true.)
        call s%add_keyword('beam', 'line', [int_field('first_node', lower=1), &
                                            real_field('x1', 'm'), real_field('y1', 'm'), real_field('x2', 'm'), &
                                            real_field('y2', 'm'), int_field('elements', lower=1), int_field('section', lower=1)], &
                           'Generator: nodes first_node..first_node+elements equally spaced from (x1, y1) to '// &
                           '(x2, y2) and the elements between them; existing coincident nodes are reused.', &
                           repeatable=.true.)
        call s%add_keyword('beam', 'polar_line', [int_field('first_node', lower=1), &
                                                  real_field('x1', 'm'), real_field('y1', 'm'), positive('length', 'm'), &
                                                  real_field('angle_deg', 'deg'), int_field('elements', lower=1), &
                                                  int_field('section', lower=1)], &
                           'Generator like line, from (x1, y1) over the given length in the direction '// &
                           'angle_deg from the x axis (counter-clockwise): the end is (x1 + length cos '// &
                           'angle, y1 + length sin angle).', repeatable=.true.)
        call s%add_keyword('beam', 'element', [int_field('id', lower=1), &
                                               int_field('node1', lower=1), int_field('node2', lower=1), &
                                               int_field('section', lower=1)], &
                           'An element from node1 to node2 with the given section.', repeatable=.true.)
        call s%add_keyword('beam', 'fix', [int_field('node', lower=1)], &
                           'Clamp DOFs of a node to zero: u (x), w (y), theta (rotation), or all; x, y and '// &
                           'rot are the same DOFs under the names [particles] uses.', &
                           tails=[tail([word_field('dof', 'u w theta all x y rot')], 1, 3, cyclic=.true.)], &
                           repeatable=.true.)
        call s%add_keyword('beam', 'load', [int_field('node', lower=1), &
                                            word_field('dof', dof_words), real_field('value', 'N or N.m')], &
                           'Nodal force (u = x, w = y) or moment (theta = rot) times a time function (none: '// &
                           'constant 1; a static analysis takes its value at t = 0).', &
                           tails=[tail([int_field('function', lower=1)], 0, 1)], repeatable=.true., &
                           effective_when=unless('run', 'analysis', 'modal'))
        call s%add_hint('beam', 'force', "a nodal force is 'load = <node> x|y <value> [function]' "// &
                        "(a force along the elements: 'distributed')")
        call s%add_hint('beam', 'moment', "a nodal moment is 'load = <node> rot <value> [function]'")
        call s%add_hint('beam', 'torque', "a nodal moment is 'load = <node> rot <value> [function]'")
        call s%add_keyword('beam', 'distributed', [int_field('node_a', lower=1), &
                                                   int_field('node_b', lower=1), word_field('direction', 'x y axial transverse'), &
                                                   real_field('q_a', 'N/m')], &
                           'Distributed load on every element whose two nodes have ids from node_a to '// &
                           'node_b: force per unit length of the element in global x or y, along the '// &
                           'element axis (axial) or across it (transverse, the axis turned by +90 deg), q_a '// &
                           'at node_a varying linearly to q_b at node_b (default q_b = q_a: uniform) with '// &
                           'the projection on the chord from node_a to node_b, times a time function (none: '// &
                           'constant 1; a static analysis takes its value at t = 0). It acts through consistent '// &
                           'nodal forces and moments.', &
                           tails=[tail([real_field('q_b', 'N/m'), int_field('function', lower=1)], 0, 2)], &
                           repeatable=.true., effective_when=unless('run', 'analysis', 'modal'))
        call s%add_keyword('beam', 'gravity', [real_field('gx', 'm/s^2'), real_field('gy', 'm/s^2')], &
                           'Gravity acceleration: self-weight density area (gx, gy) per unit length on every '// &
                           'element (the default is none; write gravity = 0 -9.81 for the usual one).', &
                           default='0 0', effective_when=unless('run', 'analysis', 'modal'))
        call s%add_hint('beam', 'damping', "damping is Rayleigh's: 'rayleigh = <a0> <a1>' (C = a0 M + a1 K)")
        call s%add_keyword('beam', 'rayleigh', &
                           [real_field('a0', '1/s', lower=0.0_wp), real_field('a1', 's', lower=0.0_wp)], &
                           'Rayleigh damping C = a0 M + a1 K.', default='0 0', allowed_when=when('run', 'analysis', 'dynamic'))
    end subroutine add_beam

    !> [modal]: natural modes.
    subroutine add_modal(s)
        !> Schema to extend.
        type(schema_t), intent(inout) :: s
        call s%add_section('modal', 'Natural modes (modal analysis).')
        call s%add_keyword('modal', 'modes', [int_field('modes', lower=1)], &
                           'Number of lowest modes to compute.', default='3', allowed_when=when('run', 'analysis', 'modal'))
    end subroutine add_modal

    !> [initial]: initial conditions.
    subroutine add_initial(s)
        !> Schema to extend.
        type(schema_t), intent(inout) :: s
        call s%add_section('initial', &
                           'Initial conditions on free DOFs (dynamic analysis); the others start at zero.')
        call s%add_keyword('initial', 'velocity', [int_field('node', lower=1), &
                                                   word_field('dof', dof_words), real_field('value', 'm/s or rad/s')], &
                           'Initial velocity of one DOF of a node.', repeatable=.true., &
                           allowed_when=when('run', 'analysis', 'dynamic'))
        call s%add_keyword('initial', 'displacement', [int_field('node', lower=1), &
                                                       word_field('dof', dof_words), real_field('value', 'm or rad')], &
                           'Initial displacement of one DOF of a node.', repeatable=.true., &
                           allowed_when=when('run', 'analysis', 'dynamic'))
        call s%add_keyword('initial', 'rigid', [int_field('node_a', lower=1), int_field('node_b', lower=1), &
                                                real_field('vx', 'm/s'), real_field('vy', 'm/s'), &
                                                real_field('omega', 'rad/s'), &
                                                real_field('xc', 'm'), real_field('yc', 'm')], &
                           'Initial velocity of a rigid motion of the nodes with ids from node_a to node_b: '// &
                           'translation (vx, vy) plus rotation omega about (xc, yc), so that a node at (x, y) '// &
                           'gets u = vx - omega (y - yc), w = vy + omega (x - xc), theta = omega; a fixed DOF '// &
                           'must get zero from it. Records apply after the velocity records.', repeatable=.true.)
    end subroutine add_initial
end module io_schema_fem
