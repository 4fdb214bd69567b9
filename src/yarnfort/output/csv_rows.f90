! SPDX-License-Identifier: MIT
!> The one writer of the rows of the output CSV tables (curve.csv, reactions.csv,
!> contacts.csv): fields joined by commas, rows by newlines, built in place (appending
!> to a growing string would copy it for every field), reals with 17 significant digits
!> so that they read back exactly.
module yarnfort_output_csv_rows
    use yarnfort_kinds, only: wp
    use yarnfort_text, only: format_integer
    implicit none
    private

    public :: csv_rows_type, format_csv_real

    !> Rows of a table being built; `get` gives them without a newline after the last.
    type :: csv_rows_type
        private
        character(len=:), allocatable :: buffer
        integer :: used = 0
        !> The next field starts a row (no comma before it).
        logical :: row_start = .true.
    contains
        !> End the current row (the next field starts a new one).
        procedure :: new_row
        !> Append a field (text, an integer or a real) or one field per real of an array.
        generic :: add => add_text, add_integer, add_real, add_reals
        procedure, private :: add_text, add_integer, add_real, add_reals
        !> The rows so far.
        procedure :: get
    end type csv_rows_type

contains

    subroutine new_row(self)
        class(csv_rows_type), intent(inout) :: self

        self%row_start = .true.
    end subroutine new_row

    subroutine add_text(self, text)
        class(csv_rows_type), intent(inout) :: self
        character(len=*), intent(in) :: text
        character(len=:), allocatable :: grown

        if (.not. allocated(self%buffer)) allocate(character(len=1024) :: self%buffer)
        if (self%used + len(text) + 1 > len(self%buffer)) then
            allocate(character(len=2 * (len(self%buffer) + len(text))) :: grown)
            grown(:self%used) = self%buffer(:self%used)
            call move_alloc(grown, self%buffer)
        end if
        if (self%row_start .and. self%used > 0) call put(achar(10))
        if (.not. self%row_start) call put(',')
        call put(text)
        self%row_start = .false.
    contains
        subroutine put(piece)
            character(len=*), intent(in) :: piece
            self%buffer(self%used + 1:self%used + len(piece)) = piece
            self%used = self%used + len(piece)
        end subroutine put
    end subroutine add_text

    subroutine add_integer(self, value)
        class(csv_rows_type), intent(inout) :: self
        integer, intent(in) :: value

        call self%add_text(format_integer(value))
    end subroutine add_integer

    subroutine add_real(self, value)
        class(csv_rows_type), intent(inout) :: self
        real(wp), intent(in) :: value

        call self%add_text(format_csv_real(value))
    end subroutine add_real

    subroutine add_reals(self, values)
        class(csv_rows_type), intent(inout) :: self
        real(wp), intent(in) :: values(:)
        integer :: i

        do i = 1, size(values)
            call self%add_text(format_csv_real(values(i)))
        end do
    end subroutine add_reals

    function get(self) result(rows)
        class(csv_rows_type), intent(in) :: self
        character(len=:), allocatable :: rows

        rows = ''
        if (allocated(self%buffer)) rows = self%buffer(:self%used)
    end function get

    !> A real with 17 significant digits (es24.16e3, the tables' number format).
    pure function format_csv_real(value) result(text)
        real(wp), intent(in) :: value
        character(len=:), allocatable :: text
        character(len=32) :: buffer

        write(buffer, '(es24.16e3)') value
        text = trim(adjustl(buffer))
    end function format_csv_real

end module yarnfort_output_csv_rows
