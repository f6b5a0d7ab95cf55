!> The deck's time functions ([functions]): read once for every model (the beam's loads, the
!> continuum's, the particles' drives), with the checks across records (unique ids,
!> increasing table times). Each `kind` word builds its extension of `time_function_t`.
module driver_config_timefunc
    use core_kinds, only: wp
    use core_error, only: error_t, make_input_error, make_internal_error
    use core_strings, only: string_t, to_str
    use core_timefunc, only: time_function_slot_t
    use core_timefunc_constant, only: constant_function_t
    use core_timefunc_ramp, only: ramp_function_t
    use core_timefunc_step, only: step_function_t
    use core_timefunc_table, only: table_function_t
    use core_timefunc_harmonic, only: harmonic_function_t
    use io_deck, only: deck_t, deck_entry_t
    implicit none
    private
    public :: build_time_functions

contains

    !> The deck's [functions], for every model (the beam's loads, the continuum's, the
    !> particles' drives): the functions in file order and their deck ids, with unique ids and
    !> increasing table times.
    subroutine build_time_functions(deck, functions, ids, error)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> Time functions, in the order of the `function` records.
        type(time_function_slot_t), allocatable, intent(out) :: functions(:)
        !> Deck id of each function.
        integer, allocatable, intent(out) :: ids(:)
        !> Error (duplicate id, table times not increasing), if any.
        type(error_t), allocatable, intent(out) :: error
        type(deck_entry_t), allocatable :: list(:)
        type(deck_entry_t) :: e
        type(string_t), allocatable :: times(:)
        real(wp), allocatable :: pairs(:)
        type(table_function_t) :: table
        integer :: i, j, n
        allocate (list, source=deck%records('functions', 'function'))
        n = size(list)
        allocate (functions(n), ids(n))
        do i = 1, n
            e = list(i)
            ids(i) = e%int('id')
            j = findloc(ids(:i - 1), ids(i), dim=1)
            if (j > 0) then
                call make_input_error(error, deck%file, e%line, 'function', &
                                      'duplicate function id '// &
                                      to_str(ids(i))//': already defined on line '//to_str(list(j)%line))
                return
            end if
            select case (e%word('kind'))
            case ('constant')
                allocate (functions(i)%fn, source=constant_function_t(c=e%real('c')))
            case ('ramp')
                allocate (functions(i)%fn, source=ramp_function_t(t1=e%real('t1')))
            case ('step')
                allocate (functions(i)%fn, source=step_function_t(t0=e%real('t0')))
            case ('harmonic')
                allocate (functions(i)%fn, source=harmonic_function_t(freq=e%real('freq'), phase=e%real('phase')))
            case ('table')
                ! Components set one by one: gfortran 12 drops the last element of a strided
                ! section (pairs(2::2)) passed to a structure constructor in allocate's source=.
                pairs = e%reals_from('t')
                table%t = pairs(1::2)
                table%f = pairs(2::2)
                times = e%words_from('t')
                do j = 2, size(table%t)
                    if (table%t(j) <= table%t(j - 1)) then
                        call make_input_error(error, deck%file, e%line, 'function', &
                                              'table times must increase strictly: t = '// &
                                              times(2*j - 1)%s//' follows t = '//times(2*j - 3)%s)
                        return
                    end if
                end do
                allocate (functions(i)%fn, source=table)
            case default
                ! The schema admits only the words above.
                call make_internal_error(error, 'build_time_functions', 'function kind '''//e%word('kind')// &
                                         ''' has no time function type')
                return
            end select
        end do
    end subroutine build_time_functions
end module driver_config_timefunc
