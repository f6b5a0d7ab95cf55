!> The FE side's energy accounts in the audit of a coupled system (coupling_coupled_step
!> `coupled_energies`), as a family: whose terms stand for the FE body.
!>
!> - `integrator_accounts_t` (what `complete_coupled_system` sets): the time integrator's terms,
!>   over the free dofs. They are those of the whole body when its supports are fixed
!>   (u = v = 0 there: a beam).
!> - `fe_whole_t`: accounts over all the dofs, prescribed ones included, that the FE side's
!>   driver computes and sets after every step (a 2D continuum: its audit of the whole body,
!>   fem_continuum_dynamics `continuum_audit_t`, weighted). With a displacement prescribed in
!>   time the integrator's terms miss the energy stored through the prescribed dofs and the
!>   supports' work.
module coupling_fe_accounts
    use core_kinds, only: wp
    use fem_newmark, only: time_integrator_t
    implicit none
    private
    public :: fe_energies_t, fe_accounts_t, integrator_accounts_t, fe_whole_t

    !> The FE side's terms of the coupled audit [J].
    type :: fe_energies_t
        !> Kinetic and strain energy (weighted).
        real(wp) :: kinetic = 0.0_wp, strain = 0.0_wp
        !> Work of the loads, Rayleigh dissipation, work of the reactions on the prescribed dofs.
        real(wp) :: external_work = 0.0_wp, damping = 0.0_wp, reaction_work = 0.0_wp
        !> Kinetic + strain energy at the start.
        real(wp) :: initial = 0.0_wp
        !> The FE side's own balance (its coupling work included), zero up to round-off.
        real(wp) :: balance = 0.0_wp
    end type fe_energies_t

    !> Whose accounts stand for the FE body.
    type, abstract :: fe_accounts_t
    contains
        !> The FE side's terms, from its integrator or from the accounts set.
        procedure(accounts_energies), deferred :: energies
    end type fe_accounts_t

    abstract interface
        !> The FE side's terms of the coupled audit.
        pure function accounts_energies(self, fe, coupling_work) result(e)
            import :: fe_accounts_t, time_integrator_t, wp, fe_energies_t
            !> The accounts.
            class(fe_accounts_t), intent(in) :: self
            !> The FE time integrator (its terms over the free dofs).
            class(time_integrator_t), intent(in) :: fe
            !> Work of the coupling forces on all the FE dofs [J].
            real(wp), intent(in) :: coupling_work
            !> The terms.
            type(fe_energies_t) :: e
        end function accounts_energies
    end interface

    !> The integrator's terms (free dofs).
    type, extends(fe_accounts_t) :: integrator_accounts_t
    contains
        !> See `fe_accounts_t%energies`.
        procedure :: energies => integrator_energies
    end type integrator_accounts_t

    !> Accounts over all the FE dofs, prescribed ones included, set by the FE side's driver.
    type, extends(fe_accounts_t) :: fe_whole_t
        !> Kinetic 1/2 v.M v and strain 1/2 u.K u over all dofs.
        real(wp) :: kinetic = 0.0_wp, strain = 0.0_wp
        !> Work of the loads, Rayleigh dissipation, work of the reactions on the prescribed dofs.
        real(wp) :: external_work = 0.0_wp, damping = 0.0_wp, reaction_work = 0.0_wp
        !> Kinetic + strain energy at the start.
        real(wp) :: initial = 0.0_wp
    contains
        !> See `fe_accounts_t%energies`.
        procedure :: energies => whole_energies
    end type fe_whole_t

contains

    !> The integrator's energies and balance (its coupling work on the free dofs; nothing is
    !> prescribed in time then), no reactions' work.
    pure function integrator_energies(self, fe, coupling_work) result(e)
        !> The accounts.
        class(integrator_accounts_t), intent(in) :: self
        !> The FE time integrator.
        class(time_integrator_t), intent(in) :: fe
        !> Work of the coupling forces on all the FE dofs [J] (the integrator's own is used).
        real(wp), intent(in) :: coupling_work
        !> The terms.
        type(fe_energies_t) :: e
        e%kinetic = fe%kinetic
        e%strain = fe%strain
        e%external_work = fe%external_work
        e%damping = fe%damping_dissipation
        e%reaction_work = 0.0_wp
        e%initial = fe%initial_energy
        e%balance = fe%energy_balance()
    end function integrator_energies

    !> The accounts set, and their balance with the coupling work on all the dofs.
    pure function whole_energies(self, fe, coupling_work) result(e)
        !> The accounts.
        class(fe_whole_t), intent(in) :: self
        !> The FE time integrator (not used: the accounts cover its terms).
        class(time_integrator_t), intent(in) :: fe
        !> Work of the coupling forces on all the FE dofs [J].
        real(wp), intent(in) :: coupling_work
        !> The terms.
        type(fe_energies_t) :: e
        e%kinetic = self%kinetic
        e%strain = self%strain
        e%external_work = self%external_work
        e%damping = self%damping
        e%reaction_work = self%reaction_work
        e%initial = self%initial
        e%balance = e%kinetic + e%strain + e%damping - e%external_work - e%reaction_work - coupling_work - e%initial
    end function whole_energies
end module coupling_fe_accounts
