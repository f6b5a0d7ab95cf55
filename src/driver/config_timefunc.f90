!> The deck's time functions ([functions]): read once for every model (the beam's loads, the
!> continuum's, the particles' drives), with the checks across records (unique ids,
!> increasing table times).
module driver_config_timefunc
    use core_kinds, only: wp
    use core_error, only: error_t, make_input_error
    use core_strings, only: string_t, to_str
    use core_timefunc, only: time_function_t, tf_constant, tf_ramp, tf_step, tf_table, tf_harmonic
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
        type(time_function_t), allocatable, intent(out) :: functions(:)
        !> Deck id of each function.
        integer, allocatable, intent(out) :: ids(:)
        !> Error (duplicate id, table times not increasing), if any.
        type(error_t), allocatable, intent(out) :: error
        type(deck_entry_t), allocatable :: list(:)
        type(deck_entry_t) :: e
        type(string_t), allocatable :: times(:)
        real(wp), allocatable :: pairs(:)
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
            associate (f => functions(i))
                f%p = 0.0_wp
                select case (e%word('kind'))
                case ('constant')
                    f%kind = tf_constant
                    f%p(1) = e%real('c')
                case ('ramp')
                    f%kind = tf_ramp
                    f%p(1) = e%real('t1')
                case ('step')
                    f%kind = tf_step
                    f%p(1) = e%real('t0')
                case ('harmonic')
                    f%kind = tf_harmonic
                    f%p(1:2) = [e%real('freq'), e%real('phase')]
                case ('table')
                    f%kind = tf_table
                    pairs = e%reals_from('t')
                    f%t = pairs(1::2)
                    f%f = pairs(2::2)
                    times = e%words_from('t')
                    do j = 2, size(f%t)
                        if (f%t(j) <= f%t(j - 1)) then
                            call make_input_error(error, deck%file, e%line, 'function', &
                                                  'table times must increase strictly: t = '// &
                                                  times(2*j - 1)%s//' follows t = '//times(2*j - 3)%s)
                            return
                        end if
                    end do
                end select
            end associate
        end do
    end subroutine build_time_functions
end module driver_config_timefunc
