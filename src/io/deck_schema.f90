!> The input deck schema: every section and keyword of a MULTICOR deck declared as data,
!> with its fields (type, unit, range, allowed words), whether it is required or repeatable,
!> its default and a one-line description.
!>
!> The reader (io_deck) validates a deck against a `schema_t`, and the reference
!> documentation (doc/input.md) is generated from it by `schema_markdown`. This module holds
!> the machinery (types, field builders, checks, documentation); the sections themselves are
!> declared, as data, by `add_<section>` routines in io_schema_common (run, functions, time,
!> output), io_schema_fem (beam, modal, initial) and io_schema_dem (particles, walls,
!> contacts, solver). `multicor_schema` (submodule io_deck_schema_multicor) puts them
!> together in documentation order.
!>
!> A keyword has fixed fields, then optionally a variable-length tail: a list of values
!> whose count lies in [min_values, max_values], possibly made of repeated groups (pairs of a
!> table). The tail may depend on a word field (the selector): `function = 1 table 0 0 1 1`
!> takes the tail declared for `table`.
!>
!> A name field (`field_name`) is a word that names something the deck does not list: a path
!> or a set of a mesh. It alone may be written in double quotes (`"left edge"`), which lets it
!> hold blanks and `#` (the reader, io_deck, takes the quotes off).
!>
!> A selection field (`field_selection`) names particles: a number `n`, a range `a:b` (either
!> end may be `last`), `last` or `all`. Its syntax is checked here; whether the numbers exist
!> is checked when the model is built.
module io_deck_schema
    use core_kinds, only: wp
    use core_strings, only: string_t, split_words, join_words, to_str, parse_real, parse_int, shorten, is_real_syntax, &
                            to_lower
    implicit none
    private
    public :: field_spec_t, tail_spec_t, condition_t, keyword_spec_t, section_spec_t, schema_t
    public :: field_int, field_real, field_word, field_text, field_selection, field_name
    public :: int_field, real_field, positive, word_field, name_field, text_field, selection_field, tail, when, unless
    public :: multicor_schema, schema_markdown, type_name, parse_selection

    !> Field type: integer.
    integer, parameter :: field_int = 1
    !> Field type: real number.
    integer, parameter :: field_real = 2
    !> Field type: one word (from a list of allowed words when one is given).
    integer, parameter :: field_word = 3
    !> Field type: free text, the rest of the line (comment stripped); only as the single field.
    integer, parameter :: field_text = 4
    !> Field type: a selection of particles: `n`, `a:b` (`last` allowed at either end),
    !> `last` or `all`.
    integer, parameter :: field_selection = 5
    !> Field type: a name (a path, a set of a mesh): any word, or any text in double quotes.
    integer, parameter :: field_name = 6

    !> One value of a keyword: name, type, unit, range, allowed words.
    type :: field_spec_t
        !> Name shown in documentation and messages.
        character(len=:), allocatable :: name
        !> field_int, field_real, field_word, field_text, field_selection or field_name.
        integer :: value_type = field_real
        !> SI unit ('' when dimensionless or not a number).
        character(len=:), allocatable :: unit
        !> Whether a lower bound applies.
        logical :: has_lower = .false.
        !> Lower bound excluded (x > lower) instead of included (x >= lower).
        logical :: lower_strict = .false.
        !> Lower bound.
        real(wp) :: lower = 0.0_wp
        !> Whether an upper bound applies.
        logical :: has_upper = .false.
        !> Upper bound excluded (x < upper) instead of included (x <= upper).
        logical :: upper_strict = .false.
        !> Upper bound.
        real(wp) :: upper = 0.0_wp
        !> Allowed words (field_word only; size 0 = any word).
        type(string_t), allocatable :: allowed(:)
    contains
        !> Check one token against the field; explain the problem when it is not valid.
        procedure :: check => field_check
        !> Text of the allowed range or words ('' when anything goes).
        procedure :: constraint => field_constraint
    end type field_spec_t

    !> Variable-length tail of a record: values after the fixed fields.
    type :: tail_spec_t
        !> Selector word this tail belongs to ('' when the keyword has a single tail).
        character(len=:), allocatable :: when
        !> Fields of the tail, in order; with `cyclic`, the group repeats.
        type(field_spec_t), allocatable :: fields(:)
        !> Least number of values.
        integer :: min_values = 0
        !> Largest number of values (-1 = no limit).
        integer :: max_values = -1
        !> The fields repeat as a group (the count must be a multiple of the group size).
        logical :: cyclic = .false.
    contains
        !> Field spec of the i-th tail value.
        procedure :: field => tail_field
        !> Usage text, e.g. `t f ... (groups of 2, at least 2 groups)`.
        procedure :: usage => tail_usage
    end type tail_spec_t

    !> Condition "[section] keyword = word" (or, negated, "is not word") on another keyword's
    !> first field; a numeric field is compared by value (`1.0` is `1`).
    type :: condition_t
        !> Whether the condition is in use.
        logical :: active = .false.
        !> Whether the condition is "keyword is not word".
        logical :: negate = .false.
        !> Section of the keyword tested.
        character(len=:), allocatable :: section
        !> Keyword tested.
        character(len=:), allocatable :: keyword
        !> Value of its first field that makes the condition true.
        character(len=:), allocatable :: word
    contains
        !> Text `[section] keyword = word`.
        procedure :: text => condition_text
    end type condition_t

    !> One keyword of the deck.
    type :: keyword_spec_t
        !> Section it belongs to.
        character(len=:), allocatable :: section
        !> Keyword name.
        character(len=:), allocatable :: name
        !> Fixed fields, in order.
        type(field_spec_t), allocatable :: fields(:)
        !> Index of the word field that selects the tail (0 = single or no tail).
        integer :: selector = 0
        !> Tails (at most one when selector = 0).
        type(tail_spec_t), allocatable :: tails(:)
        !> Must appear in every deck.
        logical :: required = .false.
        !> Must appear when this condition holds.
        type(condition_t) :: required_when
        !> May only appear when this condition holds.
        type(condition_t) :: allowed_when
        !> Has an effect only when this condition holds: elsewhere it is accepted with a
        !> warning (a tuning value left in a deck while another setting turns it off).
        type(condition_t) :: effective_when
        !> May appear several times (a record); scalar keywords appear at most once.
        logical :: repeatable = .false.
        !> Whether a default applies when the keyword is absent.
        logical :: has_default = .false.
        !> Default values as they would be written in the deck.
        character(len=:), allocatable :: default
        !> One-line description.
        character(len=:), allocatable :: description
    contains
        !> Tail for a given selector word (0 if none).
        procedure :: tail_index => keyword_tail_index
        !> Usage text, e.g. `id young density area inertia`.
        procedure :: usage => keyword_usage
        !> Names of the values of a line, blank-separated: fixed fields, then the fields of the
        !> tail for a selector word (of every tail when the word is absent).
        procedure :: field_names => keyword_field_names
    end type keyword_spec_t

    !> One `[section]` of the deck.
    type :: section_spec_t
        !> Section name.
        character(len=:), allocatable :: name
        !> One-line description.
        character(len=:), allocatable :: description
    end type section_spec_t

    !> A word that is not a keyword of a section but that users write for one (`moment` for a
    !> particle `force ... rot`): the error on it says what to write instead.
    type :: hint_spec_t
        !> Section.
        character(len=:), allocatable :: section
        !> The word written.
        character(len=:), allocatable :: word
        !> What to write instead.
        character(len=:), allocatable :: text
    end type hint_spec_t

    !> The whole schema: sections and keywords in documentation order.
    type :: schema_t
        !> Sections.
        type(section_spec_t), allocatable :: sections(:)
        !> Keywords.
        type(keyword_spec_t), allocatable :: keywords(:)
        !> Words that are not keywords, with what to write instead.
        type(hint_spec_t), allocatable :: hints(:)
    contains
        !> Declare a section.
        procedure :: add_section => schema_add_section
        !> Declare a keyword.
        procedure :: add_keyword => schema_add_keyword
        !> Index of a section (0 if unknown).
        procedure :: find_section => schema_find_section
        !> Index of a keyword in a section (0 if unknown).
        procedure :: find_keyword => schema_find_keyword
        !> Declare a word that is not a keyword, with what to write instead.
        procedure :: add_hint => schema_add_hint
        !> What to write instead of a word that is not a keyword ('' if none declared).
        procedure :: hint => schema_hint
    end type schema_t

    interface
        !> The complete MULTICOR deck schema (sections in documentation order).
        module function multicor_schema() result(s)
            !> The schema.
            type(schema_t) :: s
        end function multicor_schema
    end interface

contains

    ! ---------------------------------------------------------------------------------------
    ! Builders
    ! ---------------------------------------------------------------------------------------

    !> An integer field, optionally bounded (bounds included).
    pure function int_field(name, lower, upper) result(f)
        !> Field name.
        character(len=*), intent(in) :: name
        !> Least allowed value.
        integer, intent(in), optional :: lower
        !> Largest allowed value.
        integer, intent(in), optional :: upper
        type(field_spec_t) :: f
        f%name = name
        f%value_type = field_int
        f%unit = ''
        allocate (f%allowed(0))
        if (present(lower)) then
            f%has_lower = .true.
            f%lower = real(lower, wp)
        end if
        if (present(upper)) then
            f%has_upper = .true.
            f%upper = real(upper, wp)
        end if
    end function int_field

    !> A real field with a unit, optionally bounded (bounds included unless `*_strict`).
    pure function real_field(name, unit, lower, upper, lower_strict, upper_strict) result(f)
        !> Field name.
        character(len=*), intent(in) :: name
        !> SI unit ('' if dimensionless).
        character(len=*), intent(in) :: unit
        !> Lower bound.
        real(wp), intent(in), optional :: lower
        !> Upper bound.
        real(wp), intent(in), optional :: upper
        !> Exclude the lower bound (x > lower).
        logical, intent(in), optional :: lower_strict
        !> Exclude the upper bound (x < upper).
        logical, intent(in), optional :: upper_strict
        type(field_spec_t) :: f
        f%name = name
        f%value_type = field_real
        f%unit = unit
        allocate (f%allowed(0))
        if (present(lower)) then
            f%has_lower = .true.
            f%lower = lower
        end if
        if (present(upper)) then
            f%has_upper = .true.
            f%upper = upper
        end if
        if (present(lower_strict)) f%lower_strict = lower_strict
        if (present(upper_strict)) f%upper_strict = upper_strict
    end function real_field

    !> A real field with a unit that must be > 0.
    pure function positive(name, unit) result(f)
        !> Field name.
        character(len=*), intent(in) :: name
        !> SI unit.
        character(len=*), intent(in) :: unit
        type(field_spec_t) :: f
        f = real_field(name, unit, lower=0.0_wp, lower_strict=.true.)
    end function positive

    !> A word field; `allowed` lists the valid words separated by blanks ('' = any word).
    pure function word_field(name, allowed) result(f)
        !> Field name.
        character(len=*), intent(in) :: name
        !> Allowed words, blank-separated.
        character(len=*), intent(in) :: allowed
        type(field_spec_t) :: f
        f%name = name
        f%value_type = field_word
        f%unit = ''
        call split_words(allowed, f%allowed)
    end function word_field

    !> A name field: a path or the name of a set of a mesh, any word; it may be written in
    !> double quotes to hold blanks or `#` (`"left edge"`), unlike the other fields.
    pure function name_field(name) result(f)
        !> Field name.
        character(len=*), intent(in) :: name
        type(field_spec_t) :: f
        f%name = name
        f%value_type = field_name
        f%unit = ''
        allocate (f%allowed(0))
    end function name_field

    !> A free-text field: the rest of the line.
    pure function text_field(name) result(f)
        !> Field name.
        character(len=*), intent(in) :: name
        type(field_spec_t) :: f
        f%name = name
        f%value_type = field_text
        f%unit = ''
        allocate (f%allowed(0))
    end function text_field

    !> A selection of particles: `n`, `a:b` (`last` allowed at either end), `last` or `all`.
    pure function selection_field(name) result(f)
        !> Field name.
        character(len=*), intent(in) :: name
        type(field_spec_t) :: f
        f%name = name
        f%value_type = field_selection
        f%unit = ''
        allocate (f%allowed(0))
    end function selection_field

    !> Parse a selection of items numbered 1..n: `k` (1 <= k), `a:b` (1 <= a <= b, either end
    !> may be `last` = n), `last` (= n) or `all` (= 1:n). On success [first, last_item] is the
    !> range; numbers above n are reported as out of range (pass n = huge(1) to check the
    !> syntax only). On failure `message` says what is expected.
    subroutine parse_selection(token, n, first, last_item, ok, message, noun)
        !> The selection as written.
        character(len=*), intent(in) :: token
        !> Number of items.
        integer, intent(in) :: n
        !> First and last selected items.
        integer, intent(out) :: first, last_item
        !> Whether the selection is valid.
        logical, intent(out) :: ok
        !> Explanation when not valid ('' otherwise).
        character(len=:), allocatable, intent(out) :: message
        !> What the items are, plural, for messages (default 'items').
        character(len=*), intent(in), optional :: noun
        character(len=*), parameter :: expected = &
                                       "expected a number, a range 'a:b' (a <= b, 'last' allowed at either end), "// &
                                       "'last' or 'all'"
        integer :: colon
        message = ''
        first = 0
        last_item = 0
        ok = .false.
        colon = index(token, ':')
        if (token == 'all') then
            first = 1
            last_item = n
            ok = .true.
        else if (colon == 0) then
            call end_value(token, first)
            last_item = first
        else
            call end_value(token(:colon - 1), first)
            if (.not. ok) return
            call end_value(token(colon + 1:), last_item)
            if (ok .and. first > last_item) then
                ok = .false.
                message = "empty range '"//shorten(token)//"': the first number must not exceed the last"
                return
            end if
        end if
        if (.not. ok) return
        if (last_item > n) then
            ok = .false.
            if (present(noun)) then
                message = "selection '"//shorten(token)//"' is out of range: there are "//to_str(n)// &
                          ' '//noun//' (1..'//to_str(n)//')'
            else
                message = "selection '"//shorten(token)//"' is out of range: there are "//to_str(n)// &
                          ' items (1..'//to_str(n)//')'
            end if
        end if
    contains
        !> One end of a range: a number >= 1 or `last`.
        subroutine end_value(text, value)
            character(len=*), intent(in) :: text
            integer, intent(out) :: value
            value = 0
            if (text == 'last') then
                value = n
                ok = .true.
                return
            end if
            call parse_int(text, value, ok)
            if (ok) ok = value >= 1
            if (.not. ok) message = "bad selection '"//shorten(token)//"': "//expected
        end subroutine end_value
    end subroutine parse_selection

    !> A record tail: `fields` (repeated as a group if `cyclic`), between `min_values` and
    !> `max_values` values (-1 = no limit); `selected_by` is the selector word, if any.
    pure function tail(fields, min_values, max_values, cyclic, selected_by) result(t)
        !> Fields of the tail.
        type(field_spec_t), intent(in) :: fields(:)
        !> Least number of values.
        integer, intent(in) :: min_values
        !> Largest number of values (-1 = no limit).
        integer, intent(in) :: max_values
        !> The fields repeat as a group.
        logical, intent(in), optional :: cyclic
        !> Selector word.
        character(len=*), intent(in), optional :: selected_by
        type(tail_spec_t) :: t
        allocate (t%fields, source=fields)
        t%min_values = min_values
        t%max_values = max_values
        if (present(cyclic)) t%cyclic = cyclic
        t%when = ''
        if (present(selected_by)) t%when = selected_by
    end function tail

    !> Condition "[section] keyword = word".
    pure function when(section, keyword, word) result(c)
        !> Section of the keyword tested.
        character(len=*), intent(in) :: section
        !> Keyword tested.
        character(len=*), intent(in) :: keyword
        !> Value of its first field.
        character(len=*), intent(in) :: word
        type(condition_t) :: c
        c%active = .true.
        c%section = section
        c%keyword = keyword
        c%word = word
    end function when

    !> Condition "[section] keyword is not word".
    pure function unless(section, keyword, word) result(c)
        !> Section of the keyword tested.
        character(len=*), intent(in) :: section
        !> Keyword tested.
        character(len=*), intent(in) :: keyword
        !> Value of its first field that makes the condition false.
        character(len=*), intent(in) :: word
        type(condition_t) :: c
        c = when(section, keyword, word)
        c%negate = .true.
    end function unless

    !> Declare a section.
    subroutine schema_add_section(self, name, description)
        !> The schema.
        class(schema_t), intent(inout) :: self
        !> Section name.
        character(len=*), intent(in) :: name
        !> One-line description.
        character(len=*), intent(in) :: description
        type(section_spec_t) :: sec
        if (.not. allocated(self%sections)) allocate (self%sections(0))
        sec%name = name
        sec%description = description
        self%sections = [self%sections, sec]
    end subroutine schema_add_section

    !> Declare a keyword of an already declared section.
    subroutine schema_add_keyword(self, section, name, fields, description, required, repeatable, &
                                  default, selector, tails, required_when, allowed_when, effective_when)
        !> The schema.
        class(schema_t), intent(inout) :: self
        !> Section.
        character(len=*), intent(in) :: section
        !> Keyword name.
        character(len=*), intent(in) :: name
        !> Fixed fields.
        type(field_spec_t), intent(in) :: fields(:)
        !> One-line description.
        character(len=*), intent(in) :: description
        !> Must appear in every deck.
        logical, intent(in), optional :: required
        !> May appear several times.
        logical, intent(in), optional :: repeatable
        !> Default values as written in a deck.
        character(len=*), intent(in), optional :: default
        !> Index of the word field selecting the tail.
        integer, intent(in), optional :: selector
        !> Tails.
        type(tail_spec_t), intent(in), optional :: tails(:)
        !> Required when this condition holds.
        type(condition_t), intent(in), optional :: required_when
        !> Allowed only when this condition holds.
        type(condition_t), intent(in), optional :: allowed_when
        !> Effective only when this condition holds (a warning elsewhere).
        type(condition_t), intent(in), optional :: effective_when
        type(keyword_spec_t) :: kw
        if (.not. allocated(self%keywords)) allocate (self%keywords(0))
        kw%section = section
        kw%name = name
        kw%fields = fields
        kw%description = description
        if (present(required)) kw%required = required
        if (present(repeatable)) kw%repeatable = repeatable
        kw%default = ''
        if (present(default)) then
            kw%has_default = .true.
            kw%default = default
        end if
        if (present(selector)) kw%selector = selector
        if (present(tails)) then
            kw%tails = tails
        else
            allocate (kw%tails(0))
        end if
        if (present(required_when)) kw%required_when = required_when
        if (present(allowed_when)) kw%allowed_when = allowed_when
        if (present(effective_when)) kw%effective_when = effective_when
        self%keywords = [self%keywords, kw]
    end subroutine schema_add_keyword

    !> Declare a word of an already declared section that is not one of its keywords, with
    !> what to write instead (the unknown-keyword error gives it rather than the closest name).
    subroutine schema_add_hint(self, section, word, text)
        !> The schema.
        class(schema_t), intent(inout) :: self
        !> Section.
        character(len=*), intent(in) :: section
        !> The word users write.
        character(len=*), intent(in) :: word
        !> What to write instead.
        character(len=*), intent(in) :: text
        type(hint_spec_t) :: h
        if (.not. allocated(self%hints)) allocate (self%hints(0))
        h%section = section
        h%word = word
        h%text = text
        self%hints = [self%hints, h]
    end subroutine schema_add_hint

    !> What to write instead of `word` in `section` ('' when no hint is declared for it): the
    !> word compared in lower case and without a final 's' (`Moment`, `moments`).
    pure function schema_hint(self, section, word) result(text)
        !> The schema.
        class(schema_t), intent(in) :: self
        !> Section.
        character(len=*), intent(in) :: section
        !> The word written.
        character(len=*), intent(in) :: word
        !> The hint.
        character(len=:), allocatable :: text
        character(len=:), allocatable :: singular
        integer :: k
        text = ''
        if (.not. allocated(self%hints)) return
        singular = to_lower(word)
        if (len(singular) > 1) then
            if (singular(len(singular):) == 's') singular = singular(:len(singular) - 1)
        end if
        do k = 1, size(self%hints)
            if (self%hints(k)%section == section .and. self%hints(k)%word == singular) then
                text = self%hints(k)%text
                return
            end if
        end do
    end function schema_hint

    !> Index of a section in the schema (0 if unknown).
    pure integer function schema_find_section(self, name) result(k)
        !> The schema.
        class(schema_t), intent(in) :: self
        !> Section name.
        character(len=*), intent(in) :: name
        do k = 1, size(self%sections)
            if (self%sections(k)%name == name) return
        end do
        k = 0
    end function schema_find_section

    !> Index of a keyword of a section in the schema (0 if unknown).
    pure integer function schema_find_keyword(self, section, name) result(k)
        !> The schema.
        class(schema_t), intent(in) :: self
        !> Section name.
        character(len=*), intent(in) :: section
        !> Keyword name.
        character(len=*), intent(in) :: name
        do k = 1, size(self%keywords)
            if (self%keywords(k)%section == section .and. self%keywords(k)%name == name) return
        end do
        k = 0
    end function schema_find_keyword

    ! ---------------------------------------------------------------------------------------
    ! Field, tail and keyword helpers
    ! ---------------------------------------------------------------------------------------

    !> Name of a field type as used in messages and documentation.
    pure function type_name(value_type) result(name)
        !> field_int, field_real, field_word, field_text, field_selection or field_name.
        integer, intent(in) :: value_type
        character(len=:), allocatable :: name
        select case (value_type)
        case (field_int)
            name = 'integer'
        case (field_real)
            name = 'real'
        case (field_word)
            name = 'word'
        case (field_selection)
            name = 'selection'
        case (field_name)
            name = 'name'
        case default
            name = 'text'
        end select
    end function type_name

    !> Check a token against a field: type, range, allowed words. On failure, `message`
    !> says what is expected and what was found (e.g. "expected a real number, got 'abc'").
    subroutine field_check(self, token, ok, message)
        !> The field.
        class(field_spec_t), intent(in) :: self
        !> The token as written.
        character(len=*), intent(in) :: token
        !> Whether the token is valid.
        logical, intent(out) :: ok
        !> Explanation when not valid ('' otherwise).
        character(len=:), allocatable, intent(out) :: message
        real(wp) :: x
        integer :: i, j
        message = ''
        select case (self%value_type)
        case (field_int)
            call parse_int(token, i, ok)
            if (.not. ok) then
                message = "expected an integer, got '"//shorten(token)//"'"
                return
            end if
            x = real(i, wp)
        case (field_real)
            call parse_real(token, x, ok)
            if (.not. ok) then
                message = "expected a real number, got '"//shorten(token)//"'"
                ! a number of the right form out of the range read (parse_real)
                if (is_real_syntax(token)) message = "expected a real number with 1e-307 <= |x| < 1e308 "// &
                                                     "(or 0), got '"//shorten(token)//"'"
                return
            end if
        case (field_word)
            ok = size(self%allowed) == 0
            do i = 1, size(self%allowed)
                if (self%allowed(i)%s == token) ok = .true.
            end do
            if (.not. ok) message = "'"//shorten(token)//"' is not allowed: expected one of "// &
                                    join_words(self%allowed, ', ')
            return
        case (field_selection)
            call parse_selection(token, huge(1), i, j, ok, message)
            return
        case (field_name)
            ok = len(token) > 0
            if (.not. ok) message = 'a name is not empty'
            return
        case default
            ok = .true.
            return
        end select
        ok = .true.
        if (self%has_lower) then
            if (self%lower_strict) then
                ok = x > self%lower
            else
                ok = x >= self%lower
            end if
        end if
        if (ok .and. self%has_upper) then
            if (self%upper_strict) then
                ok = x < self%upper
            else
                ok = x <= self%upper
            end if
        end if
        if (.not. ok) message = 'out of range: must be '//self%constraint()//", got '"//shorten(token)//"'"
    end subroutine field_check

    !> Allowed range (`> 0`, `>= 0 and <= 0.5`) or words (`u, w, theta`); '' if unconstrained.
    function field_constraint(self) result(text)
        !> The field.
        class(field_spec_t), intent(in) :: self
        character(len=:), allocatable :: text
        text = ''
        if (self%value_type == field_word) then
            text = join_words(self%allowed, ', ')
            return
        end if
        if (self%value_type == field_selection) then
            text = 'n, a:b, last, all'
            return
        end if
        if (self%has_lower) then
            if (self%lower_strict) then
                text = '> '//bound_text(self, self%lower)
            else
                text = '>= '//bound_text(self, self%lower)
            end if
        end if
        if (self%has_upper) then
            if (len(text) > 0) text = text//' and '
            if (self%upper_strict) then
                text = text//'< '//bound_text(self, self%upper)
            else
                text = text//'<= '//bound_text(self, self%upper)
            end if
        end if
    end function field_constraint

    !> A bound as text: integer for integer fields.
    function bound_text(field, x) result(text)
        !> The field.
        type(field_spec_t), intent(in) :: field
        !> The bound.
        real(wp), intent(in) :: x
        character(len=:), allocatable :: text
        if (field%value_type == field_int) then
            text = to_str(nint(x))
        else
            text = to_str(x)
        end if
    end function bound_text

    !> Field spec of the i-th value of a tail (i >= 1).
    function tail_field(self, i) result(f)
        !> The tail.
        class(tail_spec_t), intent(in) :: self
        !> Position in the tail.
        integer, intent(in) :: i
        type(field_spec_t) :: f
        if (self%cyclic) then
            f = self%fields(modulo(i - 1, size(self%fields)) + 1)
        else
            f = self%fields(min(i, size(self%fields)))
        end if
    end function tail_field

    !> Usage of a tail: names, `[optional]` ones, or `group ...` with the count.
    function tail_usage(self) result(text)
        !> The tail.
        class(tail_spec_t), intent(in) :: self
        character(len=:), allocatable :: text
        integer :: i, g
        text = ''
        g = size(self%fields)
        if (self%cyclic) then
            do i = 1, g
                if (i > 1) text = text//' '
                text = text//self%fields(i)%name
            end do
            if (g == 1) then
                text = text//' ... ('//count_text(self%min_values, self%max_values, 'value')//')'
            else
                text = text//' ... ('// &
                       count_text(self%min_values/g, group_max(self%max_values, g), 'group')// &
                       ' of '//to_str(g)//')'
            end if
        else
            ! The last field repeats up to max_values: 'component [component]', 'dof [dof] [dof]'.
            do i = 1, max(g, self%max_values)
                if (i > 1) text = text//' '
                if (i > self%min_values) then
                    text = text//'['//self%fields(min(i, g))%name//']'
                else
                    text = text//self%fields(min(i, g))%name
                end if
            end do
            if (self%max_values < 0) text = text//' ...'
        end if
    end function tail_usage

    !> "1 to 3 values", "at least 2 groups", "exactly 1 value", "none or 1 group".
    function count_text(lo, hi, noun) result(text)
        !> Least count.
        integer, intent(in) :: lo
        !> Largest count (< 0: no limit).
        integer, intent(in) :: hi
        !> What is counted (singular).
        character(len=*), intent(in) :: noun
        character(len=:), allocatable :: text
        if (hi < 0) then
            text = 'at least '//to_str(lo)//' '//noun//'s'
        else if (hi == lo .and. lo == 1) then
            text = 'exactly 1 '//noun
        else if (lo == 0 .and. hi == 1) then
            text = 'none or 1 '//noun
        else if (hi == lo) then
            text = 'exactly '//to_str(lo)//' '//noun//'s'
        else
            text = to_str(lo)//' to '//to_str(hi)//' '//noun//'s'
        end if
    end function count_text

    !> Largest number of groups of size g in max_values values (-1 if no limit).
    pure integer function group_max(max_values, g) result(n)
        !> Largest number of values (-1 if no limit).
        integer, intent(in) :: max_values
        !> Group size.
        integer, intent(in) :: g
        n = -1
        if (max_values >= 0) n = max_values/g
    end function group_max

    !> Index of the tail applying when the selector field holds `word` (0 if none).
    pure integer function keyword_tail_index(self, word) result(k)
        !> The keyword.
        class(keyword_spec_t), intent(in) :: self
        !> Selector word ('' when the keyword has no selector).
        character(len=*), intent(in) :: word
        if (self%selector == 0) then
            k = min(size(self%tails), 1)
            return
        end if
        do k = 1, size(self%tails)
            if (self%tails(k)%when == word) return
        end do
        k = 0
    end function keyword_tail_index

    !> Usage of a keyword: its field names and the tail for the selector word `word`
    !> (e.g. `node dof value [function]`).
    function keyword_usage(self, word) result(text)
        !> The keyword.
        class(keyword_spec_t), intent(in) :: self
        !> Selector word ('' if none).
        character(len=*), intent(in) :: word
        character(len=:), allocatable :: text
        integer :: i, k
        text = ''
        do i = 1, size(self%fields)
            if (i > 1) text = text//' '
            text = text//self%fields(i)%name
        end do
        k = self%tail_index(word)
        if (k > 0) text = text//' '//self%tails(k)%usage()
    end function keyword_usage

    !> Names of the values of a line, separated by single blanks, in value order: the fixed
    !> fields, then the fields of the tail that applies for the selector word `word` (one
    !> group of a repeated tail); without `word`, the fields of every tail (for a keyword
    !> absent from the deck, whose values are all absent anyway).
    pure function keyword_field_names(self, word) result(names)
        !> The keyword.
        class(keyword_spec_t), intent(in) :: self
        !> Selector word ('' when the keyword has no selector).
        character(len=*), intent(in), optional :: word
        character(len=:), allocatable :: names
        integer :: i, k
        names = ''
        do i = 1, size(self%fields)
            call append(self%fields(i)%name)
        end do
        do k = 1, size(self%tails)
            if (present(word)) then
                if (k /= self%tail_index(word)) cycle
            end if
            do i = 1, size(self%tails(k)%fields)
                call append(self%tails(k)%fields(i)%name)
            end do
        end do

    contains

        !> Append one name.
        pure subroutine append(name)
            character(len=*), intent(in) :: name
            if (len(names) > 0) names = names//' '
            names = names//name
        end subroutine append
    end function keyword_field_names

    !> Text of a condition: `[run] analysis = dynamic`.
    function condition_text(self) result(text)
        !> The condition.
        class(condition_t), intent(in) :: self
        character(len=:), allocatable :: text
        if (self%negate) then
            text = '['//self%section//'] '//self%keyword//' is not '//self%word
        else
            text = '['//self%section//'] '//self%keyword//' = '//self%word
        end if
    end function condition_text

    ! ---------------------------------------------------------------------------------------
    ! Reference documentation
    ! ---------------------------------------------------------------------------------------

    !> Markdown reference of the deck: one table per section (keyword, values, unit, default,
    !> allowed, description), lines separated by LF, ending with LF. `multicor
    !> --schema-markdown` prints exactly this; doc/input.md holds it between the markers.
    subroutine schema_markdown(s, text)
        !> The schema.
        type(schema_t), intent(in) :: s
        !> The Markdown text.
        character(len=:), allocatable, intent(out) :: text
        character(len=*), parameter :: lf = new_line('a')
        integer :: i, k
        text = ''
        do i = 1, size(s%sections)
            if (i > 1) text = text//lf
            text = text//'### ['//s%sections(i)%name//']'//lf//lf//s%sections(i)%description//lf//lf
            text = text//'| keyword | values | unit | default | allowed | description |'//lf
            text = text//'|---|---|---|---|---|---|'//lf
            do k = 1, size(s%keywords)
                if (s%keywords(k)%section == s%sections(i)%name) then
                    call keyword_rows(s%keywords(k), text)
                end if
            end do
        end do
    end subroutine schema_markdown

    !> Append the table rows of one keyword: one row per field and tail field.
    subroutine keyword_rows(kw, text)
        !> The keyword.
        type(keyword_spec_t), intent(in) :: kw
        !> Text to append to.
        character(len=:), allocatable, intent(inout) :: text
        character(len=:), allocatable :: first, default, description, values
        integer :: i, j
        logical :: started
        first = '`'//kw%name//'`'
        if (kw%repeatable) first = first//' (repeatable)'
        if (kw%required) then
            default = 'required'
        else if (kw%required_when%active) then
            default = 'required if '//kw%required_when%text()
        else if (kw%has_default) then
            default = '`'//kw%default//'`'
            if (len(kw%default) == 0) default = '(empty)'
        else
            default = '-'
        end if
        description = kw%description
        if (kw%allowed_when%active) description = description//' Only allowed if '// &
                                                  kw%allowed_when%text()//'.'
        if (kw%effective_when%active) description = description//' Effective only if '// &
                                                    kw%effective_when%text()//' (elsewhere accepted with a warning).'
        started = .false.
        do i = 1, size(kw%fields)
            values = '`'//kw%fields(i)%name//'` ('//type_name(kw%fields(i)%value_type)//')'
            call add_row(kw%fields(i), values)
        end do
        do j = 1, size(kw%tails)
            do i = 1, size(kw%tails(j)%fields)
                values = ''
                if (len(kw%tails(j)%when) > 0) values = 'if `'//kw%fields(kw%selector)%name// &
                                                        '` = '//kw%tails(j)%when//': '
                values = values//'`'//kw%tails(j)%fields(i)%name//'` ('// &
                         type_name(kw%tails(j)%fields(i)%value_type)//tail_note(kw%tails(j), i)//')'
                call add_row(kw%tails(j)%fields(i), values)
            end do
        end do

    contains

        !> One table row; keyword, default and description on the first row only.
        subroutine add_row(field, values)
            type(field_spec_t), intent(in) :: field
            character(len=*), intent(in) :: values
            character(len=*), parameter :: lf = new_line('a')
            if (.not. started) then
                text = text//'|'//cell(first)//cell(values)//cell(field%unit)//cell(default)// &
                       cell(field%constraint())//cell(description)//lf
                started = .true.
            else
                text = text//'|'//cell('')//cell(values)//cell(field%unit)//cell('')// &
                       cell(field%constraint())//cell('')//lf
            end if
        end subroutine add_row

        !> A table cell followed by its closing bar: ` x |`, or ` |` when empty.
        function cell(content) result(c)
            character(len=*), intent(in) :: content
            character(len=:), allocatable :: c
            if (len(content) == 0) then
                c = ' |'
            else
                c = ' '//content//' |'
            end if
        end function cell
    end subroutine keyword_rows

    !> Note on a tail field: optional, or repeated with its count (", 1 to 3 values").
    function tail_note(t, i) result(note)
        !> The tail.
        type(tail_spec_t), intent(in) :: t
        !> Field index in the tail.
        integer, intent(in) :: i
        character(len=:), allocatable :: note
        integer :: g
        g = size(t%fields)
        note = ''
        if (t%cyclic) then
            if (i == 1) then
                if (g == 1) then
                    note = ', repeated: '//count_text(t%min_values, t%max_values, 'value')
                else
                    note = ', repeated with the next: '// &
                           count_text(t%min_values/g, group_max(t%max_values, g), 'group')
                end if
            end if
        else if (i > t%min_values) then
            note = ', optional'
        end if
    end function tail_note
end module io_deck_schema
