!> Values typed with their unit (`section = 1 210e9 Pa 7800 ...`, `step = 1e-3 s`,
!> `E = 210GPa`, `row = ... -90 deg`): the deck takes plain numbers, in SI units but for the
!> fields whose unit the schema gives otherwise (an angle in deg), and the error on a record
!> holding a unit gets a hint saying so, from the unit of the value concerned.
module io_unit_words
    use core_strings, only: is_real_syntax, shorten, to_lower
    implicit none
    private
    public :: unit_hint, looks_like_unit

    !> Units a user may type after a value (SI and their usual multiples, and a few others).
    character(len=*), parameter :: units(*) = [character(len=8) :: &
                                               'Pa', 'kPa', 'MPa', 'GPa', 'N/m2', 'N/m^2', 'N/mm2', 'N/mm^2', &
                                               'N', 'kN', 'MN', 'N/m', 'kN/m', 'N.m', 'Nm', 'kN.m', 'kNm', &
                                               'm', 'mm', 'cm', 'km', 'um', 'µm', 'm2', 'm^2', 'mm2', 'mm^2', 'm4', 'm^4', &
                                               'mm4', 'mm^4', 's', 'ms', 'us', 'µs', 'sec', &
                                               'kg', 'kg/m', 'kg/m2', 'kg/m3', 'kg/m^3', 't/m3', 'g/cm3', &
                                               'rad', 'deg', '°', 'Hz', 'kHz', 'rad/s', 'm/s', 'm/s2', 'm/s^2']

    !> The SI symbols a unit of the schema is made of when it is an SI unit (`N/m or N`,
    !> `kg/m^3`, `1/s`); a schema unit with another word (`deg`) is not.
    character(len=*), parameter :: si_symbols(*) = [character(len=3) :: 'm', 's', 'kg', 'N', 'Pa', 'rad', 'Hz', 'J', 'W']

contains

    !> Whether `token` is a unit (case aside, see `is_unit`) or a number glued to one (`210GPa`).
    pure logical function looks_like_unit(token)
        !> The value as written.
        character(len=*), intent(in) :: token
        character(len=:), allocatable :: number
        call split_unit(token, number, looks_like_unit)
    end function looks_like_unit

    !> "; 'Pa' looks like a unit: ..." when `token` is a unit (case aside) or a number glued to
    !> one (`210GPa`), '' otherwise. The value the unit belongs to is `label` (`value 7
    !> (angle_deg)`), whose unit in the schema is `field_unit`: for an SI unit or none, the
    !> hint says that a value is a plain number in SI units; for another (`deg`), that the
    !> value is in that unit, with the number to write (`write -90 without its unit`).
    pure function unit_hint(token, previous, label, field_unit) result(hint)
        !> The value as written.
        character(len=*), intent(in) :: token
        !> The value written before it ('' when none): the number a unit written alone follows.
        character(len=*), intent(in) :: previous
        !> The value the unit belongs to, for the message (`value 7 (angle_deg)`, `--end`).
        character(len=*), intent(in) :: label
        !> Its unit in the schema ('' when dimensionless).
        character(len=*), intent(in) :: field_unit
        character(len=:), allocatable :: hint
        character(len=*), parameter :: rule = ': a value is a plain number in SI units (m, s, kg, N, Pa, rad: '// &
                                       '210 GPa is 210e9), written without its unit (doc/input.md, Units)'
        character(len=:), allocatable :: number, typed
        logical :: found
        hint = ''
        call split_unit(token, number, found)
        if (.not. found) return
        typed = token(len(number) + 1:)
        if (len(number) == 0) then
            hint = "; '"//shorten(token)//"' looks like a unit"
            if (is_real_syntax(previous)) number = previous
        else
            hint = "; '"//shorten(token)//"' looks like a number with its unit"
        end if
        if (is_si(field_unit)) then
            hint = hint//rule
            return
        end if
        hint = hint//': '//label//' is in '//field_unit
        if (same_unit(typed, field_unit)) then
            if (len(number) > 0) then
                hint = hint//', write '//shorten(number)//' without its unit'
            else
                hint = hint//', written without its unit'
            end if
        else
            hint = hint//', not '//typed//': write it in '//field_unit//', without its unit'
        end if
    end function unit_hint

    !> Whether `token` is a unit or a number glued to one, and that number ('' for a unit alone).
    pure subroutine split_unit(token, number, found)
        character(len=*), intent(in) :: token
        character(len=:), allocatable, intent(out) :: number
        logical, intent(out) :: found
        integer :: j
        number = ''
        found = is_unit(token)
        if (found) return
        do j = len(token) - 1, 1, -1
            if (.not. is_unit(token(j + 1:))) cycle
            if (.not. is_real_syntax(token(:j))) cycle
            number = token(:j)
            found = .true.
            return
        end do
    end subroutine split_unit

    !> Whether the unit typed is the schema's unit (`deg`, `DEG` or `°` for `deg`).
    pure logical function same_unit(typed, field_unit)
        character(len=*), intent(in) :: typed, field_unit
        same_unit = to_lower(typed) == to_lower(field_unit)
        if (field_unit == 'deg') same_unit = same_unit .or. typed == '°'
    end function same_unit

    !> Whether a unit of the schema is SI (or none): made of SI symbols, exponents, `/`, `.`
    !> and `or` (`N/m or N`, `m/s^2`, `1/s`).
    pure logical function is_si(unit)
        character(len=*), intent(in) :: unit
        character(len=*), parameter :: separators = ' /^.*0123456789'
        integer :: i, j
        is_si = .true.
        i = 1
        do while (i <= len(unit))
            if (scan(unit(i:i), separators) > 0) then
                i = i + 1
                cycle
            end if
            j = i
            do while (j < len(unit))
                if (scan(unit(j + 1:j + 1), separators) > 0) exit
                j = j + 1
            end do
            if (unit(i:j) /= 'or' .and. all(si_symbols /= unit(i:j))) then
                is_si = .false.
                return
            end if
            i = j + 1
        end do
    end function is_si

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
            if (is_unit) return
        end do
    end function is_unit

end module io_unit_words
