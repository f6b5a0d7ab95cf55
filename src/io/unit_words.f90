!> Values typed with their unit (`section = 1 210e9 Pa 7800 ...`, `step = 1e-3 s`,
!> `E = 210GPa`): the deck takes plain numbers in SI units, and the error on such a value (a
!> unit where a number is expected, or one value too many) gets a hint saying so.
module io_unit_words
    use core_strings, only: is_real_syntax, shorten, to_lower
    implicit none
    private
    public :: unit_hint

    !> Units a user may type after a value (SI and their usual multiples, and a few others).
    character(len=*), parameter :: units(*) = [character(len=8) :: &
                                               'Pa', 'kPa', 'MPa', 'GPa', 'N/m2', 'N/m^2', 'N/mm2', 'N/mm^2', &
                                               'N', 'kN', 'MN', 'N/m', 'kN/m', 'N.m', 'Nm', 'kN.m', 'kNm', &
                                               'm', 'mm', 'cm', 'km', 'um', 'µm', 'm2', 'm^2', 'mm2', 'mm^2', 'm4', 'm^4', &
                                               'mm4', 'mm^4', 's', 'ms', 'us', 'µs', 'sec', &
                                               'kg', 'kg/m', 'kg/m2', 'kg/m3', 'kg/m^3', 't/m3', 'g/cm3', &
                                               'rad', 'deg', '°', 'Hz', 'kHz', 'rad/s', 'm/s', 'm/s2', 'm/s^2']

contains

    !> "; 'Pa' looks like a unit: ..." when `token` is a unit (case aside) or a number glued to
    !> one (`210GPa`), '' otherwise.
    pure function unit_hint(token) result(hint)
        !> The value as written.
        character(len=*), intent(in) :: token
        character(len=:), allocatable :: hint
        character(len=*), parameter :: rule = ': a value is a plain number in SI units (m, s, kg, N, Pa, rad: '// &
                                       '210 GPa is 210e9), written without its unit (doc/input.md, Units)'
        integer :: j
        hint = ''
        if (is_unit(token)) then
            hint = "; '"//shorten(token)//"' looks like a unit"//rule
            return
        end if
        do j = len(token) - 1, 1, -1
            if (.not. is_unit(token(j + 1:))) cycle
            if (.not. is_real_syntax(token(:j))) cycle
            hint = "; '"//shorten(token)//"' looks like a number with its unit"//rule
            return
        end do
    end function unit_hint

    !> Whether `word` is one of the units, compared without case (`pa`, `MPA`) but for the
    !> one-letter units N, m and s (`n`, `M` and `S` are no units typed in a deck).
    pure logical function is_unit(word)
        character(len=*), intent(in) :: word
        integer :: k
        is_unit = .false.
        if (len(word) == 0 .or. len(word) > len(units)) return
        do k = 1, size(units)
            if (len(word) == 1) then
                is_unit = word == units(k)
            else
                is_unit = to_lower(word) == to_lower(trim(units(k)))
            end if
            if (is_unit) then
                is_unit = .true.
                return
            end if
        end do
    end function is_unit

end module io_unit_words
