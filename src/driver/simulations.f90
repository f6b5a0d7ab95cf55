!> Which kind of run a deck asks for, from its sections: [beam] alone is a finite-element run,
!> [particles] alone a discrete-element run, both a coupled (Arlequin) run that needs a
!> [coupling] section; [coupling] without both models is an error. [continuum] alone is a 2D
!> continuum run; [continuum] with [particles] and [coupling] a coupled continuum-disk run.
module driver_simulations
    use core_error, only: error_t, make_input_error
    use io_deck, only: deck_t
    use driver_config_dem, only: deck_has_particles, deck_has_beam
    use driver_config_coupling, only: deck_has_coupling
    use driver_simulation, only: simulation_t
    use driver_simulation_beam, only: beam_simulation_t
    use driver_simulation_dem, only: dem_simulation_t
    use driver_simulation_coupled, only: coupled_simulation_t
    use driver_simulation_continuum, only: continuum_simulation_t, deck_has_continuum
    use driver_simulation_coupled2d, only: coupled2d_simulation_t
    implicit none
    private
    public :: select_simulation

contains

    !> The simulation extension for the deck (not yet initialised).
    subroutine select_simulation(deck, sim, error)
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        !> The simulation of the deck's kind.
        class(simulation_t), allocatable, intent(out) :: sim
        !> Set when the sections do not make a kind of run.
        type(error_t), allocatable, intent(out) :: error
        logical :: particles, coupled
        integer :: k
        particles = deck_has_particles(deck)
        coupled = particles .and. deck_has_beam(deck)
        if (deck_has_continuum(deck)) then
            if (deck_has_beam(deck) .or. (particles .neqv. deck_has_coupling(deck))) then
                call make_input_error(error, deck%file, deck%line('run', 'analysis'), '', &
                                      'a [continuum] deck cannot have [beam], and couples [particles] only with '// &
                                      'a [coupling] section (region lines): run the continuum alone, or give both '// &
                                      '[particles] and [coupling]')
                return
            end if
            if (particles) then
                allocate (coupled2d_simulation_t :: sim)
            else
                allocate (continuum_simulation_t :: sim)
            end if
            return
        end if
        if (coupled .and. .not. deck_has_coupling(deck)) then
            call make_input_error(error, deck%file, deck%line('run', 'analysis'), '', &
                                  'this deck has both [beam] and [particles]: coupled runs need a '// &
                                  '[coupling] section (at least overlap = s_fe s_particle and thickness; '// &
                                  'doc/input.md), or run the beam and the particles apart')
            return
        else if (.not. coupled .and. deck_has_coupling(deck)) then
            do k = 1, size(deck%entries)
                if (deck%entries(k)%section == 'coupling') exit
            end do
            call make_input_error(error, deck%file, deck%entries(k)%line, &
                                  deck%entries(k)%keyword, '[coupling] glues particles to a beam, and this '// &
                                  'deck has no '//trim(merge('[particles]', '[beam]     ',.not. particles))// &
                                  ': remove [coupling] or add the missing model')
            return
        end if
        if (coupled) then
            allocate (coupled_simulation_t :: sim)
        else if (particles) then
            allocate (dem_simulation_t :: sim)
        else
            allocate (beam_simulation_t :: sim)
        end if
    end subroutine select_simulation
end module driver_simulations
