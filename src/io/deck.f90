!> Reader of plain-text input decks, validated against a declarative schema (io_deck_schema).
!>
!> Syntax: `[section]` headers, then `keyword = value value ...` lines; `#` starts a comment
!> that runs to the end of the line; blank lines and tabs are fine. Lines end with LF, CR LF
!> or a lone CR (old Mac files); a UTF-8 byte-order mark at the start of the file is skipped;
!> another control character outside a comment is an error, and a NUL byte anywhere (the
!> deck is stored in the results as a C string), as are bytes that are not UTF-8 outside a
!> comment (in a comment they are a warning, `deck%warnings`, and U+FFFD in the text stored
!> with the results) and invisible Unicode spaces (core_utf8) outside a comment, a quoted name
!> or the text of a text keyword. A value is a word; a name (schema
!> `field_name`: a path, a set of a mesh) may instead be written between double quotes, which
!> makes blanks and `#` part of it; quotes elsewhere, left open, empty or glued to a word are
!> errors naming the column. A text keyword (`title`) keeps the rest of the line up to the
!> first `#`, quotes and all. Every line is checked
!> against the schema as it is read (known section and keyword, number of values, types,
!> ranges, allowed words, duplicates of scalar keywords); then required keywords and
!> conditional ones (`required_when`, `allowed_when`) are checked. The first problem found
!> stops the reading with an error `file:line: keyword 'kw': message`. A keyword given where
!> another setting turns it off (schema `effective_when`) is valid: `deck%ineffective()` lists
!> the warnings to print.
!>
!> Access after a successful read:
!> - `deck%has(section, keyword)`, `deck%count(...)`, `deck%line(...)` (first line, 0 if absent);
!> - scalars with schema defaults: `deck%get_real(section, keyword, field)`, `get_int`,
!>   `get_word`, `get_text` (field defaults to 1); a keyword absent from the deck and without
!>   default gives 0 or '' (check `has` first);
!> - records: `e = deck%record(section, keyword, i)` (i-th occurrence in file order) or
!>   `list = deck%records(section, keyword)` (all of them), then `e%line`, `e%n_values()`,
!>   and the values by the schema's field names, as fpm reads its manifest by key:
!>   `e%int('elements')`, `e%real('x0')`, `e%word('dof')`, `e%has('gap')` (an optional
!>   value is given), `e%reals_from('t')` and `e%words_from('dof')` (that value and all
!>   after it: a repeated tail). `deck%get_real(section, keyword, 'gy')` reads a field of a
!>   scalar keyword by name likewise. The names of a line are those of its fixed fields and
!>   of the tail its selector word chooses (`function = 1 ramp 2` has `id kind t1`). A name
!>   that is not one of them is a bug in the calling code, not an input error: the program
!>   stops with an internal error. The positional forms (`e%real(k)`, ...) remain for
!>   generic code such as error messages that quote a value by its position.
module io_deck
    use core_kinds, only: wp
    use core_error, only: error_t, make_input_error, make_internal_error
    use core_strings, only: string_t, strip, split_words, join_words, is_blank_char, &
                            closest_match, parse_real, parse_int, to_str, shorten
    use core_utf8, only: invalid_utf8_column, find_invisible_space, byte_hex, replace_invalid_utf8
    use io_unit_words, only: unit_hint, looks_like_unit
    use io_deck_schema, only: schema_t, keyword_spec_t, field_spec_t, condition_t, field_text, field_name, &
                              field_real, field_int, type_name
    implicit none
    private
    public :: deck_t, deck_entry_t, read_deck, read_deck_text

    !> One validated `keyword = values` line.
    type :: deck_entry_t
        !> Section it appeared in.
        character(len=:), allocatable :: section
        !> Keyword.
        character(len=:), allocatable :: keyword
        !> Line number in the deck (0 for a value taken from the schema default).
        integer :: line = 0
        !> Values as written (for a text keyword: one token, the whole text).
        type(string_t), allocatable :: tokens(:)
        !> Names of the values, from the schema, separated by single blanks: fixed fields, then
        !> those of the tail that applies (one group of a repeated tail).
        character(len=:), allocatable :: names
    contains
        !> Number of values.
        procedure :: n_values => entry_n_values
        !> Position of a named value (an internal error stops the program if the keyword
        !> has no field of that name).
        procedure :: position => entry_position
        !> Whether the named value is given on the line (an optional tail value).
        procedure :: has => entry_has
        procedure, private :: entry_int, entry_int_named
        procedure, private :: entry_real, entry_real_named
        procedure, private :: entry_word, entry_word_named
        procedure, private :: entry_reals_from, entry_reals_from_named
        !> A value as an integer, by field name or position (0 if absent).
        generic :: int => entry_int, entry_int_named
        !> A value as a real, by field name or position (0 if absent).
        generic :: real => entry_real, entry_real_named
        !> A value as written, by field name or position ('' if absent).
        generic :: word => entry_word, entry_word_named
        !> A value and all after it as reals (a variable-length tail), by field name or
        !> position.
        generic :: reals_from => entry_reals_from, entry_reals_from_named
        !> A value and all after it as written (a variable-length tail), by field name.
        procedure :: words_from => entry_words_from
    end type deck_entry_t

    !> A validated deck.
    type :: deck_t
        !> Deck file name as given to read_deck.
        character(len=:), allocatable :: file
        !> Full text of the deck, UTF-8 throughout (to store with the results): the text read,
        !> where each byte of a comment that is not UTF-8 (a Latin-1 `é`) is the replacement
        !> character U+FFFD.
        character(len=:), allocatable :: text
        !> The text read, its bytes unchanged (a leading byte-order mark left out, lone CRs
        !> made LFs): what the deck hash of a checkpoint covers, as it did before comments
        !> that are not UTF-8 were replaced in `text`.
        character(len=:), allocatable :: source_text
        !> Warnings on the text, as 'warning: file:line: ...': bytes that are not UTF-8 in the
        !> comments.
        type(string_t), allocatable :: warnings(:)
        !> Validated entries, in file order.
        type(deck_entry_t), allocatable :: entries(:)
        !> Schema the deck was validated against (defaults come from it).
        type(schema_t) :: schema
        !> Line of the first header of each schema section (0: absent), in schema order.
        integer, allocatable :: header_lines(:)
    contains
        !> Whether a keyword appears in the deck.
        procedure :: has => deck_has
        !> Number of occurrences of a keyword.
        procedure :: count => deck_count
        !> Line of the first occurrence of a keyword (0 if absent).
        procedure :: line => deck_line
        !> i-th occurrence of a keyword (an empty entry with line 0 if there is none).
        procedure :: record => deck_record
        !> All occurrences of a keyword, in file order (one pass: use it to loop over records).
        procedure :: records => deck_records
        !> Whether any keyword of a section appears in the deck.
        procedure :: has_section => deck_has_section
        !> Line of the first `[section]` header (0 if absent).
        procedure :: header_line => deck_header_line
        procedure, private :: deck_get_real, deck_get_real_named
        procedure, private :: deck_get_int, deck_get_int_named
        procedure, private :: deck_get_word, deck_get_word_named
        !> A real value, from the deck or the schema default, by field name or position.
        generic :: get_real => deck_get_real, deck_get_real_named
        !> An integer value, from the deck or the schema default, by field name or position.
        generic :: get_int => deck_get_int, deck_get_int_named
        !> A word value, from the deck or the schema default, by field name or position.
        generic :: get_word => deck_get_word, deck_get_word_named
        !> A text value, from the deck or the schema default.
        procedure :: get_text => deck_get_text
        !> Warnings for the keywords given that have no effect (schema `effective_when`).
        procedure :: ineffective => deck_ineffective
    end type deck_t

contains

    !> Read a deck file and validate it against the schema.
    subroutine read_deck(path, schema, deck, error)
        !> Deck file.
        character(len=*), intent(in) :: path
        !> Schema to validate against.
        type(schema_t), intent(in) :: schema
        !> The deck.
        type(deck_t), intent(out) :: deck
        !> Error naming file, line and keyword, if any.
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: text
        character(len=512) :: msg
        integer :: unit, ios, n
        logical :: is_file
        inquire (file=path, exist=is_file)
        if (.not. is_file) then
            call make_input_error(error, path, 0, '', 'cannot open the deck: no such file')
            return
        end if
        open (newunit=unit, file=path, access='stream', form='unformatted', status='old', &
              action='read', iostat=ios, iomsg=msg)
        if (ios /= 0) then
            call make_input_error(error, path, 0, '', 'cannot open the deck: '//trim(msg))
            return
        end if
        inquire (unit=unit, size=n)
        allocate (character(len=max(n, 0)) :: text)
        ios = 0
        if (n > 0) read (unit, iostat=ios, iomsg=msg) text
        close (unit)
        if (ios /= 0 .or. n < 0) then
            if (n < 0) msg = 'size unknown'
            call make_input_error(error, path, 0, '', 'cannot read the deck: '//trim(msg))
            return
        end if
        call read_deck_text(path, text, schema, deck, error)
    end subroutine read_deck

    !> Validate deck text (lines separated by LF, CR LF or a lone CR; a leading UTF-8
    !> byte-order mark is skipped) against the schema; `file` is the name used in error
    !> messages.
    subroutine read_deck_text(file, raw_text, schema, deck, error)
        !> Name of the deck in messages.
        character(len=*), intent(in) :: file
        !> Deck text.
        character(len=*), intent(in) :: raw_text
        !> Schema to validate against.
        type(schema_t), intent(in) :: schema
        !> The deck.
        type(deck_t), intent(out) :: deck
        !> Error naming file, line and keyword, if any.
        type(error_t), allocatable, intent(out) :: error
        type(deck_entry_t), allocatable :: entries(:), grown(:)
        integer, allocatable :: first_line(:), section_line(:)
        character(len=:), allocatable :: current, text
        integer :: n, line_no, start, lf
        ! Line of the last header while no keyword has followed it, and the first header
        ! found with no keyword before the next header or the end (0: none).
        integer :: open_header, empty_header
        character(len=:), allocatable :: open_name, empty_name
        ! Bytes that are not UTF-8 in the comments: the lines holding them, and the first one.
        integer :: latin_lines, latin_line, latin_column
        character(len=4) :: latin_byte
        text = normalized_text(raw_text)
        open_header = 0
        empty_header = 0
        latin_lines = 0
        latin_line = 0
        latin_column = 0
        latin_byte = ''
        deck%file = file
        deck%text = text
        deck%source_text = text
        allocate (deck%warnings(0))
        deck%schema = schema
        allocate (entries(16))
        allocate (first_line(size(schema%keywords)), section_line(size(schema%sections)))
        first_line = 0
        section_line = 0
        n = 0
        current = ''
        start = 1
        line_no = 0
        do while (start <= len(text))
            lf = index(text(start:), new_line('a'))
            if (lf == 0) then
                lf = len(text) + 1
            else
                lf = start + lf - 1
            end if
            line_no = line_no + 1
            call parse_line(text(start:lf - 1))
            if (allocated(error)) return
            start = lf + 1
        end do
        call close_header()
        if (latin_lines > 0) call warn_comments_not_utf8()
        deck%entries = entries(:n)
        deck%header_lines = section_line
        if (n == 0) then
            call make_input_error(error, file, 0, '', 'the deck is empty (no keyword found); '// &
                                  'it needs at least '//required_list(schema))
            return
        end if
        call check_required(deck, first_line, section_line, error)
        if (allocated(error)) return
        ! A header followed by no keyword would have no effect (a deck of beams with an empty
        ! [particles] is still a deck of beams, a second [beam] header with nothing under it
        ! adds nothing), and is most likely what is left of a section the user meant to fill.
        if (empty_header > 0) call make_input_error(error, file, empty_header, '', '['//empty_name// &
                                                    '] has no keyword: give its keywords or remove the header')

    contains

        !> A new header or the end of the deck: the previous header, if no keyword followed it,
        !> is empty.
        subroutine close_header()
            if (open_header > 0 .and. empty_header == 0) then
                empty_header = open_header
                empty_name = open_name
            end if
            open_header = 0
        end subroutine close_header

        !> Bytes that are not UTF-8 in comments are kept in the text that is hashed (a deck
        !> that ran before they were refused continues its checkpoint) and replaced by U+FFFD
        !> in the text stored with the results, with a warning at the first of them.
        subroutine warn_comments_not_utf8()
            character(len=:), allocatable :: more
            deck%text = replace_invalid_utf8(text)
            more = ''
            if (latin_lines == 2) more = ' (1 more line has such bytes in its comment)'
            if (latin_lines > 2) more = ' ('//to_str(latin_lines - 1)//' more lines have such bytes in their comments)'
            deck%warnings = [string_t('warning: '//file//':'//to_str(latin_line)//': byte '//latin_byte// &
                                      ' at column '//to_str(latin_column)//', in a comment, is not UTF-8 text'// &
                                      more//': the results store the deck with U+FFFD in place of each; save the '// &
                                      'deck as UTF-8 (it was most likely saved as Latin-1 or Windows-1252) once no '// &
                                      'checkpoint of it is to be continued: --restart takes a checkpoint only with '// &
                                      'the deck it was written for, byte for byte')]
        end subroutine warn_comments_not_utf8

        !> A control character (other than a tab, or the CR of CR LF) outside a comment is an error: a terminal
        !> would not show it in the message, and it means a binary or damaged file.
        subroutine check_control(s)
            character(len=*), intent(in) :: s
            integer :: i
            i = control_column(s)
            if (i > 0) call make_input_error(error, file, line_no, '', 'control character '//byte_hex(s(i:i))// &
                                             ' at column '//to_str(i)//': a deck is plain text '// &
                                             '(a binary or damaged file?)')
        end subroutine check_control

        !> An invisible Unicode space (no-break, thin, zero width, ...) in a line up to its
        !> comment is an error naming it and its column: it looks like a blank but does not end
        !> a word (`11<no-break space> w` is one value). A quoted name and the text of a text
        !> keyword (title) may hold one: it is part of that text.
        subroutine check_invisible(line)
            character(len=*), intent(in) :: line
            character(len=len(line)) :: seen
            character(len=:), allocatable :: what
            integer :: i, eq_col, k, column
            logical :: inside, is_text
            seen = line
            eq_col = index(line, '=')
            if (index(strip(line), '[') == 1) eq_col = 0
            if (eq_col > 0) then
                k = 0
                if (len(current) > 0) k = schema%find_keyword(current, strip(line(:eq_col - 1)))
                is_text = .false.
                if (k > 0) is_text = schema%keywords(k)%fields(1)%value_type == field_text
                if (is_text) then
                    seen(eq_col + 1:) = ' '
                else
                    inside = .false.
                    do i = eq_col + 1, len(line)
                        if (line(i:i) == '"') inside = .not. inside
                        if (inside .or. line(i:i) == '"') seen(i:i) = ' '
                    end do
                end if
            end if
            call find_invisible_space(seen, column, what)
            if (column == 0) return
            call make_input_error(error, file, line_no, '', what//' at column '//to_str(column)// &
                                  ': an invisible character that looks like a blank but does not separate '// &
                                  'words; replace it with a plain space (or delete it)')
        end subroutine check_invisible

        !> Validate one line and store its entry.
        subroutine parse_line(raw)
            character(len=*), intent(in) :: raw
            character(len=:), allocatable :: s, key, value, message
            type(string_t), allocatable :: tokens(:)
            logical, allocatable :: quoted(:)
            integer :: hash, eq, k, raw_eq, last, glued, control
            hash = index(raw, '#')
            ! The values of a keyword line may hold double-quoted names, where '#' is no
            ! comment; those of a text keyword (title) are the rest of the line up to the first
            ! '#', quotes included, as they always were.
            raw_eq = index(raw(:merge(hash - 1, len(raw), hash > 0)), '=')
            if (raw_eq > 0) then
                k = 0
                if (len(current) > 0) k = schema%find_keyword(current, strip(raw(:raw_eq - 1)))
                if (k > 0) then
                    if (schema%keywords(k)%fields(1)%value_type /= field_text) hash = comment_column(raw, raw_eq + 1)
                else
                    hash = comment_column(raw, raw_eq + 1)
                end if
            end if
            if (hash > 0) then
                s = strip(raw(:hash - 1))
            else
                s = strip(raw)
            end if
            ! A NUL byte even in a comment: the deck is stored in the results as a C string
            ! (/deck_text, for a rerun), which would end there.
            if (hash > 0) then
                k = index(raw(hash:), achar(0))
                if (k > 0) then
                    call make_input_error(error, file, line_no, '', 'control character 0x00 (NUL) at column '// &
                                          to_str(hash + k - 1)//' in a comment: the deck is stored in the '// &
                                          'results as text, which would end there (a binary or damaged file?)')
                    return
                end if
            end if
            ! Not UTF-8 outside a comment: an error, since the results store the values and the
            ! title as UTF-8 text (/deck_text, /title), which their readers would fail to decode.
            ! In a comment, a warning: a deck with a Latin-1 comment ran before this check, and
            ! its checkpoints are continued (warn_comments_not_utf8).
            if (hash > 0) then
                k = invalid_utf8_column(raw(hash:))
                if (k > 0) then
                    latin_lines = latin_lines + 1
                    if (latin_lines == 1) then
                        latin_line = line_no
                        latin_column = hash + k - 1
                        latin_byte = byte_hex(raw(hash + k - 1:hash + k - 1))
                    end if
                end if
                k = invalid_utf8_column(raw(:hash - 1))
            else
                k = invalid_utf8_column(raw)
            end if
            ! The first offending byte is named: a control character before it (a binary file)
            ! is reported by check_control below.
            if (k > 0) then
                control = control_column(raw(:merge(hash - 1, len(raw), hash > 0)))
                if (control > 0 .and. control < k) k = 0
            end if
            if (k > 0) then
                call make_input_error(error, file, line_no, '', 'byte '//byte_hex(raw(k:k))//' at column '// &
                                      to_str(k)//' is not UTF-8 text: save the deck as UTF-8 (it was '// &
                                      'most likely saved as Latin-1 or Windows-1252)')
                return
            end if
            if (len(s) == 0) return
            if (hash > 0) then
                call check_control(raw(:hash - 1))
                if (.not. allocated(error)) call check_invisible(raw(:hash - 1))
            else
                call check_control(raw)
                if (.not. allocated(error)) call check_invisible(raw)
            end if
            if (allocated(error)) return
            if (s(1:1) == '[') then
                call parse_header(s)
                return
            end if
            eq = index(s, '=')
            if (eq == 0) then
                call split_words(s, tokens)
                call make_input_error(error, file, line_no, tokens(1)%s, &
                                      "expected 'keyword = value', found no '='")
                return
            end if
            key = strip(s(:eq - 1))
            value = strip(s(eq + 1:))
            if (len(key) == 0) then
                call make_input_error(error, file, line_no, '', "missing keyword name before '='")
                return
            end if
            if (scan(key, ' '//achar(9)) > 0) then
                call make_input_error(error, file, line_no, key, 'a keyword name is a single word')
                return
            end if
            if (len(current) == 0) then
                call make_input_error(error, file, line_no, key, &
                                      'appears before any [section] header'//home_of(schema, key, header_sections(schema, text)))
                return
            end if
            k = schema%find_keyword(current, key)
            if (k == 0) then
                call make_input_error(error, file, line_no, key, &
                                      unknown_keyword(schema, current, key, header_sections(schema, text)))
                return
            end if
            if (.not. schema%keywords(k)%repeatable .and. first_line(k) > 0) then
                call make_input_error(error, file, line_no, key, 'given twice in section ['// &
                                      current//'] (first on line '//to_str(first_line(k))// &
                                      ', again on line '//to_str(line_no)//'); it may appear only once')
                return
            end if
            if (schema%keywords(k)%fields(1)%value_type == field_text) then
                allocate (tokens(1))
                tokens(1)%s = value
                allocate (quoted(1), source=.false.)
            else
                last = len(raw)
                if (hash > 0) last = hash - 1
                call split_values(raw, raw_eq + 1, last, tokens, quoted, message)
                if (len(message) > 0) then
                    call make_input_error(error, file, line_no, key, message)
                    return
                end if
            end if
            ! A '#' glued to the text after it (`block #2.msh`) may have cut a name in two.
            glued = 0
            if (hash > 0 .and. hash < len(raw)) then
                if (.not. is_blank_char(raw(hash + 1:hash + 1))) glued = hash
            end if
            call check_values(schema%keywords(k), tokens, quoted, file, line_no, error, glued)
            if (allocated(error)) return
            if (first_line(k) == 0) first_line(k) = line_no
            open_header = 0
            if (n == size(entries)) then
                allocate (grown(2*n))
                grown(:n) = entries
                call move_alloc(grown, entries)
            end if
            n = n + 1
            entries(n)%section = current
            entries(n)%keyword = key
            entries(n)%line = line_no
            entries(n)%names = line_names(schema%keywords(k), tokens)
            call move_alloc(tokens, entries(n)%tokens)
        end subroutine parse_line

        !> Validate a `[section]` header and make it current.
        subroutine parse_header(s)
            character(len=*), intent(in) :: s
            character(len=:), allocatable :: name
            type(string_t), allocatable :: names(:)
            integer :: k, best, d
            if (s(len(s):len(s)) /= ']') then
                call make_input_error(error, file, line_no, '', "malformed section header '"// &
                                      shorten(s)//"': expected '[name]'")
                return
            end if
            name = strip(s(2:len(s) - 1))
            k = schema%find_section(name)
            if (k == 0) then
                allocate (names(size(schema%sections)))
                do k = 1, size(names)
                    names(k)%s = schema%sections(k)%name
                end do
                call closest_match(name, names, best, d)
                if (best > 0 .and. d <= tolerance(name)) then
                    call make_input_error(error, file, line_no, '', 'unknown section ['//shorten(name)// &
                                          ']; did you mean ['//names(best)%s//']? (sections: '// &
                                          join_words(names, ', ')//')')
                else
                    call make_input_error(error, file, line_no, '', 'unknown section ['//shorten(name)// &
                                          '] (sections: '//join_words(names, ', ')//')')
                end if
                return
            end if
            current = name
            if (section_line(k) == 0) section_line(k) = line_no
            call close_header()
            open_header = line_no
            open_name = name
        end subroutine parse_header
    end subroutine read_deck_text

    !> Column of the first control character of a line of a deck outside its comment (0: none):
    !> any byte below 32 or 127, but a tab and the CR of a CR LF line end.
    pure integer function control_column(s) result(column)
        !> The line up to its comment.
        character(len=*), intent(in) :: s
        integer :: i, c
        do i = 1, len(s)
            c = iachar(s(i:i))
            if (c == 13 .and. i == len(s)) cycle  ! the CR of a CR LF line end
            if ((c < 32 .and. c /= 9) .or. c == 127) then
                column = i
                return
            end if
        end do
        column = 0
    end function control_column

    !> Deck text without a leading UTF-8 byte-order mark, and with lone CRs (lines ending in
    !> CR only) turned into LFs; CR LF pairs are left for `strip`, which drops the CR.
    pure function normalized_text(raw) result(text)
        !> The file's bytes.
        character(len=*), intent(in) :: raw
        character(len=:), allocatable :: text
        ! the UTF-8 byte order mark, bytes EF BB BF (char: achar is for ASCII codes only)
        character(len=*), parameter :: bom = char(int(z'EF'))//char(int(z'BB'))//char(int(z'BF'))
        integer :: i
        if (len(raw) >= 3) then
            if (raw(1:3) == bom) then
                text = raw(4:)
            else
                text = raw
            end if
        else
            text = raw
        end if
        if (index(text, achar(13)) == 0) return
        do i = 1, len(text)
            if (text(i:i) /= achar(13)) cycle
            if (i < len(text)) then
                if (text(i + 1:i + 1) == achar(10)) cycle
            end if
            text(i:i) = achar(10)
        end do
    end function normalized_text

    !> Column of the '#' that starts the comment of line `raw`, looking from column `from` on
    !> (0 when there is none): the first '#' outside double quotes. A quote left open runs to
    !> the end of the line (split_values reports it).
    pure integer function comment_column(raw, from) result(column)
        !> The line.
        character(len=*), intent(in) :: raw
        !> First column searched (after the '=').
        integer, intent(in) :: from
        logical :: inside
        inside = .false.
        do column = from, len(raw)
            if (raw(column:column) == '"') then
                inside = .not. inside
            else if (raw(column:column) == '#' .and. .not. inside) then
                return
            end if
        end do
        column = 0
    end function comment_column

    !> The values of line `raw` between columns `first` and `last`: words separated by blanks,
    !> or values in double quotes, which may hold blanks and '#' (the quotes are not part of the
    !> value); `quoted` tells which were quoted. A quote left open, an empty or blank quoted
    !> value, a quote inside a word or a closing quote followed by more than a blank give
    !> `message` naming the column in `raw` ('' when the values are well formed).
    pure subroutine split_values(raw, first, last, tokens, quoted, message)
        !> The line.
        character(len=*), intent(in) :: raw
        !> First and last columns of the values.
        integer, intent(in) :: first, last
        !> The values, quotes taken off.
        type(string_t), allocatable, intent(out) :: tokens(:)
        !> Whether each value was written in double quotes.
        logical, allocatable, intent(out) :: quoted(:)
        !> What is wrong ('' when nothing is).
        character(len=:), allocatable, intent(out) :: message
        integer :: n
        ! Two passes, counting the values and then storing them: growing the lists one value
        ! at a time copied them each time, quadratic in the number of values (a table
        ! function of 40 000 samples took minutes to read).
        allocate (tokens(0), quoted(0))
        call scan_values(tokens, quoted, n, message)
        if (len(message) > 0) return
        deallocate (tokens, quoted)
        allocate (tokens(n), quoted(n))
        call scan_values(tokens, quoted, n, message)

    contains

        !> One pass over the values: count them in n, and store them when the lists are large
        !> enough (the second pass); `message` as for split_values.
        pure subroutine scan_values(tokens, quoted, n, message)
            type(string_t), intent(inout) :: tokens(:)
            logical, intent(inout) :: quoted(:)
            integer, intent(out) :: n
            character(len=:), allocatable, intent(out) :: message
            logical :: store
            integer :: i, j
            store = size(tokens) > 0
            message = ''
            n = 0
            i = first
            do while (i <= last)
                if (is_blank_char(raw(i:i))) then
                    i = i + 1
                else if (raw(i:i) == '"') then
                    j = index(raw(i + 1:last), '"')
                    if (j == 0) then
                        message = 'unterminated quote: the double quote at column '//to_str(i)// &
                                  ' has no closing one on its line (a quoted name ends on the line it starts)'
                        return
                    end if
                    j = i + j
                    if (len(strip(raw(i + 1:j - 1))) == 0) then
                        message = 'empty quoted value at column '//to_str(i)//': a name has at least one '// &
                                  'character other than a blank'
                        return
                    end if
                    if (j < last) then
                        if (.not. is_blank_char(raw(j + 1:j + 1))) then
                            message = 'the quoted value "'//shorten(raw(i + 1:j - 1))//'" closed at column '// &
                                      to_str(j)//' is followed by '''//raw(j + 1:j + 1)//''' (column '// &
                                      to_str(j + 1)//'): put a blank after the closing quote, or the whole name '// &
                                      'between the quotes'
                            return
                        end if
                    end if
                    n = n + 1
                    if (store) then
                        tokens(n)%s = raw(i + 1:j - 1)
                        quoted(n) = .true.
                    end if
                    i = j + 1
                else
                    j = i
                    do while (j <= last)
                        if (is_blank_char(raw(j:j))) exit
                        if (raw(j:j) == '"') then
                            message = 'double quote inside a value at column '//to_str(j)//': quotes go around '// &
                                      'a whole name ("left edge"), after a blank'
                            return
                        end if
                        j = j + 1
                    end do
                    n = n + 1
                    if (store) then
                        tokens(n)%s = raw(i:j - 1)
                        quoted(n) = .false.
                    end if
                    i = j
                end if
            end do
        end subroutine scan_values
    end subroutine split_values

    !> A noun with its indefinite article: `a real`, `an integer`.
    pure function article(noun) result(text)
        !> The noun.
        character(len=*), intent(in) :: noun
        character(len=:), allocatable :: text
        if (scan(noun(1:1), 'aeiou') > 0) then
            text = 'an '//noun
        else
            text = 'a '//noun
        end if
    end function article

    !> Names of the values of a line of keyword `spec` with values `tokens`: the fixed
    !> fields and the tail chosen by the selector word.
    pure function line_names(spec, tokens) result(names)
        !> Keyword spec.
        type(keyword_spec_t), intent(in) :: spec
        !> Values as written.
        type(string_t), intent(in) :: tokens(:)
        character(len=:), allocatable :: names
        if (spec%selector > 0 .and. spec%selector <= size(tokens)) then
            names = spec%field_names(tokens(spec%selector)%s)
        else
            names = spec%field_names('')
        end if
    end function line_names

    !> Largest Levenshtein distance at which a name is suggested for a misspelt one.
    pure integer function tolerance(name)
        !> The misspelt name.
        character(len=*), intent(in) :: name
        tolerance = max(2, len(name)/2)
    end function tolerance

    !> Message for a keyword unknown in `section`: closest name in the section, or in another
    !> section when that fits better (the section of the deck's model when the keyword is in
    !> several: `gravity` under [time] of a deck of disks goes to [particles]), and the list of
    !> the section's keywords.
    function unknown_keyword(schema, section, key, present) result(message)
        !> The schema.
        type(schema_t), intent(in) :: schema
        !> Current section.
        character(len=*), intent(in) :: section
        !> The unknown keyword.
        character(len=*), intent(in) :: key
        !> The sections whose headers the deck holds (header_sections).
        type(string_t), intent(in) :: present(:)
        character(len=:), allocatable :: message, hint, home
        type(string_t), allocatable :: local(:), everywhere(:)
        type(string_t) :: item
        integer :: k, best_local, d_local, best_all, d_all
        allocate (local(0), everywhere(0))
        do k = 1, size(schema%keywords)
            item%s = schema%keywords(k)%name
            if (schema%keywords(k)%section == section) local = [local, item]
            ! A keyword of a model's section that the deck does not have is no likely
            ! misspelling: `damping` in a continuum deck is not [coupling] `pairing`.
            if (fits_model(schema%keywords(k)%section)) everywhere = [everywhere, item]
        end do
        call closest_match(key, local, best_local, d_local)
        call closest_match(key, everywhere, best_all, d_all)
        message = 'unknown keyword in section ['//section//']'
        hint = schema%hint(section, key)
        home = home_sections(schema, key, present)
        if (len(hint) > 0) then
            message = message//'; '//hint
        else if (len(home) > 0) then
            ! The keyword itself, in another section.
            message = message//"; keyword '"//key//"' belongs to "//home
            if (index(home, 'sections ') == 1) then
                message = message//': move it to the section (or sections) it is meant for'
            else
                message = message//': move it there'
            end if
        else if (best_all > 0 .and. d_all < d_local .and. d_all <= tolerance(key)) then
            ! A better match in another section.
            message = message//"; did you mean '"//everywhere(best_all)%s//"'? keyword '"// &
                      everywhere(best_all)%s//"' belongs to "//home_sections(schema, everywhere(best_all)%s, present)
        else if (best_local > 0 .and. d_local <= tolerance(key)) then
            message = message//"; did you mean '"//local(best_local)%s//"'?"
        end if
        message = message//' (keywords of ['//section//']: '//join_words(local, ', ')//')'
    contains
        !> Whether `name` is no section of a model ([particles], [continuum], [beam], [coupling])
        !> or one the deck has (or the deck has none of them yet).
        logical function fits_model(name)
            character(len=*), intent(in) :: name
            integer :: i
            fits_model = .true.
            if (.not. is_model_section(name)) return
            if (.not. any([(is_model_section(present(i)%s), i=1, size(present))])) return
            fits_model = any([(present(i)%s == name, i=1, size(present))])
        end function fits_model
    end function unknown_keyword

    !> Whether `name` is the section of a model: [particles], [continuum], [beam] or [coupling].
    pure logical function is_model_section(name)
        !> Section name.
        character(len=*), intent(in) :: name
        is_model_section = name == 'particles' .or. name == 'continuum' .or. name == 'beam' .or. name == 'coupling'
    end function is_model_section

    !> "section [x]" for the section that keyword `key` belongs to: the only one that has it,
    !> or the only one of those that the deck has (`present`); "sections [a], [b] and [c]"
    !> when several of the deck's sections have it, or none of them and several others
    !> (`gravity` in a deck without [beam], [particles] or [continuum]); '' when no section has it.
    function home_sections(schema, key, present) result(text)
        !> The schema.
        type(schema_t), intent(in) :: schema
        !> Keyword.
        character(len=*), intent(in) :: key
        !> The sections whose headers the deck holds.
        type(string_t), intent(in) :: present(:)
        character(len=:), allocatable :: text
        type(string_t), allocatable :: homes(:), inside(:)
        type(string_t) :: item
        integer :: k, i
        allocate (homes(0), inside(0))
        do k = 1, size(schema%keywords)
            if (schema%keywords(k)%name /= key) cycle
            item%s = '['//schema%keywords(k)%section//']'
            homes = [homes, item]
            if (any([(present(i)%s == schema%keywords(k)%section, i=1, size(present))])) &
                inside = [inside, homes(size(homes))]
        end do
        if (size(inside) > 0 .and. size(homes) > 1) homes = inside
        select case (size(homes))
        case (0)
            text = ''
        case (1)
            text = 'section '//homes(1)%s
        case default
            text = 'sections '//join_words(homes(:size(homes) - 1), ', ')//' and '//homes(size(homes))%s
        end select
    end function home_sections

    !> "; it belongs to section [x]" for a keyword known in some section (home_sections), ''
    !> otherwise.
    function home_of(schema, key, present) result(text)
        !> The schema.
        type(schema_t), intent(in) :: schema
        !> Keyword.
        character(len=*), intent(in) :: key
        !> The sections whose headers the deck holds.
        type(string_t), intent(in) :: present(:)
        character(len=:), allocatable :: text
        text = home_sections(schema, key, present)
        if (len(text) > 0) text = '; it belongs to '//text
    end function home_of

    !> The known sections whose headers `text` holds, each once, in the order of the deck (the
    !> model a hint is for: what the deck has, before and after the line being read).
    function header_sections(schema, text) result(names)
        !> The schema.
        type(schema_t), intent(in) :: schema
        !> The deck's text.
        character(len=*), intent(in) :: text
        type(string_t), allocatable :: names(:)
        type(string_t) :: item
        character(len=:), allocatable :: line
        integer :: start, lf, hash, i
        allocate (names(0))
        start = 1
        do while (start <= len(text))
            lf = index(text(start:), new_line('a'))
            if (lf == 0) then
                lf = len(text) + 1
            else
                lf = start + lf - 1
            end if
            line = text(start:lf - 1)
            start = lf + 1
            hash = index(line, '#')
            if (hash > 0) line = line(:hash - 1)
            line = strip(line)
            if (len(line) < 3) cycle
            if (line(1:1) /= '[' .or. line(len(line):) /= ']') cycle
            line = strip(line(2:len(line) - 1))
            if (schema%find_section(line) == 0) cycle
            if (any([(names(i)%s == line, i=1, size(names))])) cycle
            item%s = line
            names = [names, item]
        end do
    end function header_sections

    !> "[run] analysis, ..." : the unconditionally required keywords.
    function required_list(schema) result(text)
        !> The schema.
        type(schema_t), intent(in) :: schema
        character(len=:), allocatable :: text
        integer :: k
        text = ''
        do k = 1, size(schema%keywords)
            if (schema%keywords(k)%required) then
                if (len(text) > 0) text = text//', '
                text = text//'['//schema%keywords(k)%section//'] '//schema%keywords(k)%name
            end if
        end do
    end function required_list

    !> Check the values of one line: count (fixed fields and tail), types, ranges, words, and
    !> that only names were quoted.
    subroutine check_values(spec, tokens, quoted, file, line, error, comment)
        !> Keyword spec.
        type(keyword_spec_t), intent(in) :: spec
        !> Values as written (quotes taken off).
        type(string_t), intent(in) :: tokens(:)
        !> Whether each value was written in double quotes.
        logical, intent(in) :: quoted(:)
        !> Deck name.
        character(len=*), intent(in) :: file
        !> Line number.
        integer, intent(in) :: line
        !> Error, if any.
        type(error_t), allocatable, intent(out) :: error
        !> Column of the '#' that starts the line's comment when text follows it without a blank
        !> (absent or 0: none), for the hint of a name that ran into it.
        integer, intent(in), optional :: comment
        character(len=:), allocatable :: message, selector
        integer :: nf, ntok, i, kt, g
        logical :: ok
        if (spec%fields(1)%value_type == field_text) return
        nf = size(spec%fields)
        ntok = size(tokens)
        selector = ''
        if (spec%selector > 0 .and. spec%selector <= ntok) selector = tokens(spec%selector)%s
        do i = 1, min(ntok, nf)
            call check_one(spec%fields(i), i)
            if (allocated(error)) return
        end do
        if (ntok < nf) then
            call count_error('too few')
            return
        end if
        kt = spec%tail_index(selector)
        if (kt == 0) then
            if (ntok > nf) call count_error('too many')
            return
        end if
        associate (t => spec%tails(kt))
            g = size(t%fields)
            if (ntok - nf < t%min_values) then
                call count_error('too few')
                return
            end if
            if (t%max_values >= 0 .and. ntok - nf > t%max_values) then
                call count_error('too many')
                return
            end if
            if (t%cyclic .and. modulo(ntok - nf, g) /= 0) then
                call make_input_error(error, file, line, spec%name, "incomplete group: '"// &
                                      spec%usage(selector)//"' takes values after '"// &
                                      spec%fields(nf)%name//"' in groups of "//to_str(g)// &
                                      ', got '//to_str(ntok - nf)//record_unit_hint(0))
                return
            end if
            do i = 1, ntok - nf
                call check_one(t%field(i), nf + i)
                if (allocated(error)) return
            end do
        end associate

    contains

        !> Check value k against its field: quoted only if a name, then its type and range.
        subroutine check_one(field, k)
            type(field_spec_t), intent(in) :: field
            integer, intent(in) :: k
            if (quoted(k) .and. field%value_type /= field_name) then
                call make_input_error(error, file, line, spec%name, 'value '//to_str(k)//' ('//field%name// &
                                      '): "'//shorten(tokens(k)%s)//'" is in double quotes, which are only for '// &
                                      'names (a path, a set name); '//article(type_name(field%value_type))// &
                                      ' is written without them')
                return
            end if
            call field%check(tokens(k)%s, ok, message)
            if (ok) return
            ! `1 210e9 Pa 7800`: a unit where a number is expected
            message = message//record_unit_hint(k)
            call make_input_error(error, file, line, spec%name, 'value '//to_str(k)// &
                                  ' ('//field%name//'): '//message//name_hint(k - 1, k))
        end subroutine check_one

        !> Error for a wrong number of values, with the expected usage.
        subroutine count_error(what)
            character(len=*), intent(in) :: what
            character(len=:), allocatable :: hint
            integer :: last_expected, kt_here, p, extra
            hint = ''
            if (what == 'too many') then
                ! the last value expected may be a name that went on past its first blank
                last_expected = nf
                kt_here = spec%tail_index(selector)
                if (kt_here > 0) last_expected = nf + spec%tails(kt_here)%max_values
                hint = name_hint(last_expected, ntok)
                ! or a name among the fixed fields, when the line is valid with the words after
                ! it joined into that name (`fix = left edge x y`; not `load = top x 1 2 3`)
                do p = 1, nf
                    do extra = ntok - last_expected, ntok - nf
                        if (len(hint) > 0) exit
                        if (fits_joined(p, extra)) hint = name_hint(p, p + extra)
                    end do
                end do
            end if
            ! `step = 1e-3 s`: the value's unit taken for one more value
            if (len(hint) == 0) hint = record_unit_hint(0)
            call make_input_error(error, file, line, spec%name, what//' values (got '// &
                                  to_str(ntok)//"): expected '"//spec%usage(selector)//"'"//hint)
        end subroutine count_error

        !> The hint of a record refused while it holds a unit (`-90 deg`, `210GPa`): from value
        !> k when it is one (0: none), else from the first value of the record that is one (a
        !> quoted value and one that a name or word field takes as it is, a set named `m`,
        !> aside); '' when there is none. The unit belongs to the value before it, or to the
        !> value it is glued to, and to the last value expected when the record has too many;
        !> the hint uses that value's unit in the schema (unit_hint).
        function record_unit_hint(k) result(hint)
            integer, intent(in) :: k
            character(len=:), allocatable :: hint, previous
            type(field_spec_t) :: f
            logical :: found
            integer :: p, q
            hint = ''
            do p = 0, ntok
                if (p == 0) then
                    q = k
                    if (q == 0) cycle
                else
                    q = p
                    if (q == k) cycle
                end if
                if (is_unit_value(q)) exit
            end do
            if (p > ntok) return
            ! the value the unit belongs to: the one before a unit alone, within those expected
            if (scan(tokens(q)%s(1:1), '+-.0123456789') == 0) then
                previous = ''
                if (q > 1) previous = tokens(q - 1)%s
                p = max(q - 1, 1)
            else
                previous = ''
                p = q
            end if
            p = min(p, n_expected())
            call field_at(p, f, found)
            if (found) then
                hint = unit_hint(tokens(q)%s, previous, 'value '//to_str(p)//' ('//f%name//')', f%unit)
            else
                hint = unit_hint(tokens(q)%s, previous, '', '')
            end if
        end function record_unit_hint

        !> Whether value q looks like a unit and is no value its field takes as it is.
        function is_unit_value(q) result(is_unit)
            integer, intent(in) :: q
            logical :: is_unit, found, fits
            character(len=:), allocatable :: why
            type(field_spec_t) :: f
            is_unit = .false.
            if (quoted(q)) return
            if (.not. looks_like_unit(tokens(q)%s)) return
            call field_at(q, f, found)
            if (found) then
                if (f%value_type /= field_real .and. f%value_type /= field_int) then
                    call f%check(tokens(q)%s, fits, why)
                    if (fits) return
                end if
            end if
            is_unit = .true.
        end function is_unit_value

        !> Number of values the line may have (fixed fields and the tail its selector chooses);
        !> ntok when the tail has no limit.
        integer function n_expected()
            integer :: kt_here
            n_expected = nf
            kt_here = spec%tail_index(selector)
            if (kt_here == 0) return
            if (spec%tails(kt_here)%max_values < 0) then
                n_expected = max(nf, ntok)
            else
                n_expected = nf + spec%tails(kt_here)%max_values
            end if
        end function n_expected

        !> The field of value q (found false when the line has no value q).
        subroutine field_at(q, f, found)
            integer, intent(in) :: q
            type(field_spec_t), intent(out) :: f
            logical, intent(out) :: found
            integer :: kt_here
            found = q >= 1 .and. q <= n_expected()
            if (.not. found) return
            if (q <= nf) then
                f = spec%fields(q)
                return
            end if
            kt_here = spec%tail_index(selector)
            f = spec%tails(kt_here)%field(q - nf)
        end subroutine field_at

        !> Whether the values would fit the fields if value p, a name written without quotes,
        !> took the `extra` values after it (their count, types and words; no selector among
        !> the values moved).
        logical function fits_joined(p, extra) result(fits)
            integer, intent(in) :: p, extra
            integer :: q, kt_here
            character(len=:), allocatable :: why
            type(field_spec_t) :: f
            fits = .false.
            if (extra < 1 .or. quoted(p) .or. spec%fields(p)%value_type /= field_name) return
            if (spec%selector > p) return
            do q = p + 1, nf
                call spec%fields(q)%check(tokens(q + extra)%s, fits, why)
                if (.not. fits) return
            end do
            kt_here = spec%tail_index(selector)
            fits = kt_here > 0 .or. ntok - extra == nf
            if (kt_here == 0) return
            associate (t => spec%tails(kt_here))
                fits = ntok - extra - nf >= t%min_values .and. (t%max_values < 0 .or. ntok - extra - nf <= t%max_values)
                if (t%cyclic) fits = fits .and. modulo(ntok - extra - nf, size(t%fields)) == 0
                do q = 1, ntok - extra - nf
                    if (.not. fits) return
                    f = t%field(q)
                    call f%check(tokens(nf + q + extra)%s, fits, why)
                end do
            end associate
        end function fits_joined

        !> When value p is a name written without quotes, values p + 1 .. k (the one that went
        !> wrong, or the last of too many) may be the rest of a name with blanks, split into
        !> words: the hint shows values p .. k quoted as one name; '' otherwise.
        function name_hint(p, k) result(hint)
            integer, intent(in) :: p, k
            character(len=:), allocatable :: hint, joined
            type(field_spec_t) :: f
            integer :: q, kt_here
            hint = ''
            if (p < 1 .or. p >= k .or. k > ntok) return
            if (quoted(p)) return
            if (p <= nf) then
                f = spec%fields(p)
            else
                kt_here = spec%tail_index(selector)
                if (kt_here == 0) return
                f = spec%tails(kt_here)%field(p - nf)
            end if
            if (f%value_type /= field_name) return
            joined = tokens(p)%s
            do q = p + 1, k
                joined = joined//' '//tokens(q)%s
            end do
            hint = '; if "'//shorten(joined)//'" is one name, write it in double quotes'
            ! the name may go on after a '#' (`My Meshes/block #2.msh`)
            if (present(comment) .and. k == ntok) then
                if (comment > 0) hint = hint//" (outside them '#' starts a comment, which cut the line at column "// &
                                        to_str(comment)//')'
            end if
        end function name_hint
    end subroutine check_values

    !> Check required and conditional keywords once the whole deck is read.
    subroutine check_required(deck, first_line, section_line, error)
        !> The deck (entries filled).
        type(deck_t), intent(in) :: deck
        !> First line of each schema keyword (0 if absent).
        integer, intent(in) :: first_line(:)
        !> First header line of each schema section (0 if absent).
        integer, intent(in) :: section_line(:)
        !> Error, if any.
        type(error_t), allocatable, intent(out) :: error
        integer :: k
        character(len=:), allocatable :: actual
        do k = 1, size(deck%schema%keywords)
            associate (kw => deck%schema%keywords(k))
                if (kw%required .and. first_line(k) == 0) then
                    call make_input_error(error, deck%file, &
                                          section_line(deck%schema%find_section(kw%section)), kw%name, &
                                          'missing: this keyword is required in section ['// &
                                          kw%section//'] ('//kw%name//' = '//value_hint(kw)//')')
                    return
                end if
            end associate
        end do
        do k = 1, size(deck%schema%keywords)
            associate (kw => deck%schema%keywords(k), c => deck%schema%keywords(k)%required_when)
                if (c%active .and. first_line(k) == 0) then
                    if (condition_holds(deck, c)) then
                        call make_input_error(error, deck%file, deck%line(c%section, c%keyword), &
                                              kw%name, 'missing: ['//kw%section//'] '//kw%name// &
                                              ' is required when '//c%text())
                        return
                    end if
                end if
            end associate
        end do
        do k = 1, size(deck%schema%keywords)
            associate (kw => deck%schema%keywords(k), c => deck%schema%keywords(k)%allowed_when)
                if (c%active .and. first_line(k) > 0) then
                    if (.not. condition_holds(deck, c)) then
                        actual = deck%get_word(c%section, c%keyword)
                        call make_input_error(error, deck%file, first_line(k), kw%name, &
                                              'only allowed when '//c%text()//'; here '//c%keyword// &
                                              ' = '//actual//condition_origin(deck, c)// &
                                              ': remove '//kw%name//' or set '//c%keyword//' = '//c%word)
                        return
                    end if
                end if
            end associate
        end do
    end subroutine check_required

    !> What to write after `keyword =`: field names, or the allowed words as `a|b|c`.
    function value_hint(kw) result(text)
        !> The keyword.
        type(keyword_spec_t), intent(in) :: kw
        character(len=:), allocatable :: text
        integer :: i
        text = ''
        do i = 1, size(kw%fields)
            if (i > 1) text = text//' '
            if (size(kw%fields(i)%allowed) > 0) then
                text = text//join_words(kw%fields(i)%allowed, '|')
            else
                text = text//kw%fields(i)%name
            end if
        end do
    end function value_hint

    !> Whether a condition holds in the deck: the first field of the keyword tested (or its
    !> default) is the condition's word, compared by value when both read as numbers.
    function condition_holds(deck, c) result(holds)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> The condition.
        type(condition_t), intent(in) :: c
        logical :: holds
        character(len=:), allocatable :: actual
        real(wp) :: x, y
        logical :: ok_x, ok_y
        actual = deck%get_word(c%section, c%keyword)
        call parse_real(actual, x, ok_x)
        call parse_real(c%word, y, ok_y)
        if (ok_x .and. ok_y) then
            holds = x == y
        else
            holds = actual == c%word
        end if
        if (c%negate) holds = .not. holds
    end function condition_holds

    !> Warnings for the keywords of the deck that have no effect: those whose schema
    !> `effective_when` condition does not hold, as 'warning: file:line: ...'.
    function deck_ineffective(deck) result(warnings)
        !> The deck.
        class(deck_t), intent(in) :: deck
        type(string_t), allocatable :: warnings(:)
        integer, allocatable :: lines(:)
        integer :: k, line, i
        allocate (warnings(0), lines(0))
        do k = 1, size(deck%schema%keywords)
            associate (kw => deck%schema%keywords(k), c => deck%schema%keywords(k)%effective_when)
                if (.not. c%active) cycle
                line = deck%line(kw%section, kw%name)
                if (line == 0) cycle
                if (condition_holds(deck, c)) cycle
                ! in the order of the deck's lines
                i = count(lines <= line) + 1
                lines = [lines(1:i - 1), line, lines(i:)]
                warnings = [warnings(1:i - 1), string_t('warning: '//deck%file//':'//to_str(line)//': ['// &
                                                        kw%section//'] '//kw%name//' has no effect: it applies only '// &
                                                        'when '//c%text()//'; here '//c%keyword//' = '// &
                                                        deck%get_word(c%section, c%keyword)//condition_origin(deck, c)), &
                            warnings(i:)]
            end associate
        end do
    end function deck_ineffective

    !> " (line N)" or " (default)": where the value tested by a condition comes from.
    function condition_origin(deck, c) result(text)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> The condition.
        type(condition_t), intent(in) :: c
        character(len=:), allocatable :: text
        integer :: line
        line = deck%line(c%section, c%keyword)
        if (line > 0) then
            text = ' (line '//to_str(line)//')'
        else
            text = ' (default)'
        end if
    end function condition_origin

    ! ---------------------------------------------------------------------------------------
    ! Access
    ! ---------------------------------------------------------------------------------------

    !> Index in `entries` of the i-th occurrence of a keyword (0 if none).
    pure integer function find_entry(self, section, keyword, i) result(idx)
        !> The deck.
        class(deck_t), intent(in) :: self
        !> Section.
        character(len=*), intent(in) :: section
        !> Keyword.
        character(len=*), intent(in) :: keyword
        !> Occurrence wanted (1 = first).
        integer, intent(in) :: i
        integer :: seen
        seen = 0
        do idx = 1, size(self%entries)
            if (self%entries(idx)%keyword == keyword .and. &
                self%entries(idx)%section == section) then
                seen = seen + 1
                if (seen == i) return
            end if
        end do
        idx = 0
    end function find_entry

    !> Whether any keyword of a section appears in the deck.
    pure logical function deck_has_section(self, section)
        !> The deck.
        class(deck_t), intent(in) :: self
        !> Section.
        character(len=*), intent(in) :: section
        integer :: idx
        deck_has_section = .false.
        do idx = 1, size(self%entries)
            if (self%entries(idx)%section == section) then
                deck_has_section = .true.
                return
            end if
        end do
    end function deck_has_section

    !> Line of the first `[section]` header of the deck (0 if the section is absent).
    pure integer function deck_header_line(self, section) result(line)
        !> The deck.
        class(deck_t), intent(in) :: self
        !> Section.
        character(len=*), intent(in) :: section
        integer :: k
        line = 0
        if (.not. allocated(self%header_lines)) return
        k = self%schema%find_section(section)
        if (k > 0 .and. k <= size(self%header_lines)) line = self%header_lines(k)
    end function deck_header_line

    !> Whether a keyword appears in the deck.
    pure logical function deck_has(self, section, keyword)
        !> The deck.
        class(deck_t), intent(in) :: self
        !> Section.
        character(len=*), intent(in) :: section
        !> Keyword.
        character(len=*), intent(in) :: keyword
        deck_has = find_entry(self, section, keyword, 1) > 0
    end function deck_has

    !> Number of occurrences of a keyword in the deck.
    pure integer function deck_count(self, section, keyword) result(n)
        !> The deck.
        class(deck_t), intent(in) :: self
        !> Section.
        character(len=*), intent(in) :: section
        !> Keyword.
        character(len=*), intent(in) :: keyword
        integer :: idx
        n = 0
        do idx = 1, size(self%entries)
            if (self%entries(idx)%keyword == keyword .and. &
                self%entries(idx)%section == section) n = n + 1
        end do
    end function deck_count

    !> Line of the first occurrence of a keyword (0 if absent).
    pure integer function deck_line(self, section, keyword) result(line)
        !> The deck.
        class(deck_t), intent(in) :: self
        !> Section.
        character(len=*), intent(in) :: section
        !> Keyword.
        character(len=*), intent(in) :: keyword
        integer :: idx
        idx = find_entry(self, section, keyword, 1)
        line = 0
        if (idx > 0) line = self%entries(idx)%line
    end function deck_line

    !> The i-th occurrence of a keyword, in file order; an entry with no values and line 0
    !> if there is no such occurrence.
    function deck_record(self, section, keyword, i) result(entry)
        !> The deck.
        class(deck_t), intent(in) :: self
        !> Section.
        character(len=*), intent(in) :: section
        !> Keyword.
        character(len=*), intent(in) :: keyword
        !> Occurrence (1 = first).
        integer, intent(in) :: i
        type(deck_entry_t) :: entry
        integer :: idx, k
        idx = find_entry(self, section, keyword, i)
        if (idx > 0) then
            entry = self%entries(idx)
        else
            entry%section = section
            entry%keyword = keyword
            allocate (entry%tokens(0))
            entry%names = ''
            k = self%schema%find_keyword(section, keyword)
            if (k > 0) entry%names = self%schema%keywords(k)%field_names()
        end if
    end function deck_record

    !> All occurrences of a keyword, in file order (size 0 if none).
    function deck_records(self, section, keyword) result(list)
        !> The deck.
        class(deck_t), intent(in) :: self
        !> Section.
        character(len=*), intent(in) :: section
        !> Keyword.
        character(len=*), intent(in) :: keyword
        type(deck_entry_t), allocatable :: list(:)
        integer :: idx, n
        allocate (list(self%count(section, keyword)))
        n = 0
        do idx = 1, size(self%entries)
            if (self%entries(idx)%keyword == keyword .and. &
                self%entries(idx)%section == section) then
                n = n + 1
                list(n) = self%entries(idx)
            end if
        end do
    end function deck_records

    !> First occurrence of a keyword, or its schema default (line 0), or an empty entry.
    function value_entry(self, section, keyword) result(entry)
        !> The deck.
        class(deck_t), intent(in) :: self
        !> Section.
        character(len=*), intent(in) :: section
        !> Keyword.
        character(len=*), intent(in) :: keyword
        type(deck_entry_t) :: entry
        integer :: k
        entry = self%record(section, keyword, 1)
        if (entry%line > 0) return
        k = self%schema%find_keyword(section, keyword)
        if (k == 0) return
        associate (kw => self%schema%keywords(k))
            if (.not. kw%has_default) return
            if (kw%fields(1)%value_type == field_text) then
                deallocate (entry%tokens)
                allocate (entry%tokens(1))
                entry%tokens(1)%s = kw%default
            else
                call split_words(kw%default, entry%tokens)
            end if
            entry%names = line_names(kw, entry%tokens)
        end associate
    end function value_entry

    !> A real value (field `field`, default 1) from the deck or the schema default.
    function deck_get_real(self, section, keyword, field) result(value)
        !> The deck.
        class(deck_t), intent(in) :: self
        !> Section.
        character(len=*), intent(in) :: section
        !> Keyword.
        character(len=*), intent(in) :: keyword
        !> Field index (default 1).
        integer, intent(in), optional :: field
        real(wp) :: value
        type(deck_entry_t) :: entry
        entry = value_entry(self, section, keyword)
        value = entry%real(field_or_1(field))
    end function deck_get_real

    !> An integer value (field `field`, default 1) from the deck or the schema default.
    function deck_get_int(self, section, keyword, field) result(value)
        !> The deck.
        class(deck_t), intent(in) :: self
        !> Section.
        character(len=*), intent(in) :: section
        !> Keyword.
        character(len=*), intent(in) :: keyword
        !> Field index (default 1).
        integer, intent(in), optional :: field
        integer :: value
        type(deck_entry_t) :: entry
        entry = value_entry(self, section, keyword)
        value = entry%int(field_or_1(field))
    end function deck_get_int

    !> A word value (field `field`, default 1) from the deck or the schema default.
    function deck_get_word(self, section, keyword, field) result(value)
        !> The deck.
        class(deck_t), intent(in) :: self
        !> Section.
        character(len=*), intent(in) :: section
        !> Keyword.
        character(len=*), intent(in) :: keyword
        !> Field index (default 1).
        integer, intent(in), optional :: field
        character(len=:), allocatable :: value
        type(deck_entry_t) :: entry
        entry = value_entry(self, section, keyword)
        value = entry%word(field_or_1(field))
    end function deck_get_word

    !> A real value, the field named `name`, from the deck or the schema default.
    function deck_get_real_named(self, section, keyword, name) result(value)
        !> The deck.
        class(deck_t), intent(in) :: self
        !> Section.
        character(len=*), intent(in) :: section
        !> Keyword.
        character(len=*), intent(in) :: keyword
        !> Field name (from the schema).
        character(len=*), intent(in) :: name
        real(wp) :: value
        type(deck_entry_t) :: entry
        entry = value_entry(self, section, keyword)
        value = entry%real(name)
    end function deck_get_real_named

    !> An integer value, the field named `name`, from the deck or the schema default.
    function deck_get_int_named(self, section, keyword, name) result(value)
        !> The deck.
        class(deck_t), intent(in) :: self
        !> Section.
        character(len=*), intent(in) :: section
        !> Keyword.
        character(len=*), intent(in) :: keyword
        !> Field name (from the schema).
        character(len=*), intent(in) :: name
        integer :: value
        type(deck_entry_t) :: entry
        entry = value_entry(self, section, keyword)
        value = entry%int(name)
    end function deck_get_int_named

    !> A word value, the field named `name`, from the deck or the schema default.
    function deck_get_word_named(self, section, keyword, name) result(value)
        !> The deck.
        class(deck_t), intent(in) :: self
        !> Section.
        character(len=*), intent(in) :: section
        !> Keyword.
        character(len=*), intent(in) :: keyword
        !> Field name (from the schema).
        character(len=*), intent(in) :: name
        character(len=:), allocatable :: value
        type(deck_entry_t) :: entry
        entry = value_entry(self, section, keyword)
        value = entry%word(name)
    end function deck_get_word_named

    !> A text value from the deck or the schema default.
    function deck_get_text(self, section, keyword) result(value)
        !> The deck.
        class(deck_t), intent(in) :: self
        !> Section.
        character(len=*), intent(in) :: section
        !> Keyword.
        character(len=*), intent(in) :: keyword
        character(len=:), allocatable :: value
        type(deck_entry_t) :: entry
        entry = value_entry(self, section, keyword)
        value = entry%word(1)
    end function deck_get_text

    !> The optional field index, 1 when absent.
    pure integer function field_or_1(field)
        !> Field index.
        integer, intent(in), optional :: field
        field_or_1 = 1
        if (present(field)) field_or_1 = field
    end function field_or_1

    !> Number of values of an entry.
    pure integer function entry_n_values(self) result(n)
        !> The entry.
        class(deck_entry_t), intent(in) :: self
        n = 0
        if (allocated(self%tokens)) n = size(self%tokens)
    end function entry_n_values

    !> k-th value as an integer (0 if absent; values were validated when read).
    integer function entry_int(self, k) result(value)
        !> The entry.
        class(deck_entry_t), intent(in) :: self
        !> Value index.
        integer, intent(in) :: k
        logical :: ok
        value = 0
        if (k >= 1 .and. k <= self%n_values()) call parse_int(self%tokens(k)%s, value, ok)
    end function entry_int

    !> k-th value as a real (0 if absent; values were validated when read).
    real(wp) function entry_real(self, k) result(value)
        !> The entry.
        class(deck_entry_t), intent(in) :: self
        !> Value index.
        integer, intent(in) :: k
        logical :: ok
        value = 0.0_wp
        if (k >= 1 .and. k <= self%n_values()) call parse_real(self%tokens(k)%s, value, ok)
    end function entry_real

    !> k-th value as written ('' if absent).
    function entry_word(self, k) result(value)
        !> The entry.
        class(deck_entry_t), intent(in) :: self
        !> Value index.
        integer, intent(in) :: k
        character(len=:), allocatable :: value
        value = ''
        if (k >= 1 .and. k <= self%n_values()) value = self%tokens(k)%s
    end function entry_word

    !> Values k, k+1, ..., n_values() as reals (size 0 if k > n_values()).
    function entry_reals_from(self, k) result(values)
        !> The entry.
        class(deck_entry_t), intent(in) :: self
        !> First value index.
        integer, intent(in) :: k
        real(wp), allocatable :: values(:)
        integer :: i
        allocate (values(max(self%n_values() - k + 1, 0)))
        do i = 1, size(values)
            values(i) = self%real(k + i - 1)
        end do
    end function entry_reals_from

    !> Position of the value named `name` among the values of the line (its first one for a
    !> repeated group). The names come from the schema, so a name that is not among them is
    !> a bug in the calling code: the program stops with an internal error.
    integer function entry_position(self, name) result(k)
        !> The entry.
        class(deck_entry_t), intent(in) :: self
        !> Field name.
        character(len=*), intent(in) :: name
        type(error_t), allocatable :: error
        character(len=:), allocatable :: padded
        integer :: at, i
        padded = ' '
        if (allocated(self%names)) padded = ' '//self%names//' '
        at = index(padded, ' '//name//' ')
        if (at == 0 .or. len(name) == 0) then
            call make_internal_error(error, 'io_deck', '['//self%section//'] '//self%keyword// &
                                     " has no value named '"//name//"' (its values: "// &
                                     strip(padded)//')')
            error stop error%message
        end if
        k = 0
        do i = 1, at
            if (padded(i:i) == ' ') k = k + 1
        end do
    end function entry_position

    !> Whether the value named `name` is given on the line (false for an optional tail value
    !> left out).
    logical function entry_has(self, name)
        !> The entry.
        class(deck_entry_t), intent(in) :: self
        !> Field name.
        character(len=*), intent(in) :: name
        entry_has = self%position(name) <= self%n_values()
    end function entry_has

    !> The value named `name` as an integer (0 if absent).
    integer function entry_int_named(self, name) result(value)
        !> The entry.
        class(deck_entry_t), intent(in) :: self
        !> Field name.
        character(len=*), intent(in) :: name
        value = self%int(self%position(name))
    end function entry_int_named

    !> The value named `name` as a real (0 if absent).
    real(wp) function entry_real_named(self, name) result(value)
        !> The entry.
        class(deck_entry_t), intent(in) :: self
        !> Field name.
        character(len=*), intent(in) :: name
        value = self%real(self%position(name))
    end function entry_real_named

    !> The value named `name` as written ('' if absent).
    function entry_word_named(self, name) result(value)
        !> The entry.
        class(deck_entry_t), intent(in) :: self
        !> Field name.
        character(len=*), intent(in) :: name
        character(len=:), allocatable :: value
        value = self%word(self%position(name))
    end function entry_word_named

    !> The value named `name` and all after it, as reals (size 0 if absent).
    function entry_reals_from_named(self, name) result(values)
        !> The entry.
        class(deck_entry_t), intent(in) :: self
        !> Field name.
        character(len=*), intent(in) :: name
        real(wp), allocatable :: values(:)
        values = self%reals_from(self%position(name))
    end function entry_reals_from_named

    !> The value named `name` and all after it, as written (size 0 if absent).
    function entry_words_from(self, name) result(values)
        !> The entry.
        class(deck_entry_t), intent(in) :: self
        !> Field name.
        character(len=*), intent(in) :: name
        type(string_t), allocatable :: values(:)
        integer :: k
        k = self%position(name)
        allocate (values(max(self%n_values() - k + 1, 0)))
        if (size(values) > 0) values = self%tokens(k:)
    end function entry_words_from
end module io_deck
