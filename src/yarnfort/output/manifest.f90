! SPDX-License-Identifier: MIT
!> The manifest of an output folder, folder/.yarnfort-manifest: every file a run wrote
!> there, so that a later run deletes only files of its own (never one named in a file
!> another tool may have written, such as a foreign states.pvd, nor a file of a name
!> this program may write that no run of it wrote, such as one's own reactions.csv).
!> One entry a line:
!>
!>     file <name>
!>     state <name> <step> <time>
!>
!> A state entry (state_NNNNN.vtu) stands for its multiblock file and its other blocks
!> too (state_NNNNN.vtm, holders_NNNNN.vtu, links_..., passages_...: yarnfort_output_vtk),
!> written before it.
!> A name is listed when the run is about to create it (add_file, add_state), before the
!> file exists: a kill in between leaves a listed file that is incomplete or missing,
!> never an unlisted one. Only names this program writes are ever taken from the file
!> (is_own_name), so a damaged or foreign manifest cannot make it delete anything else.
!> The whole file is replaced atomically (tmp + rename); entries are appended one line
!> at a time.
module yarnfort_output_manifest
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_output_filesystem, only: rename_file, remove_file, sync_file, open_append, &
        flush_checked, open_new_file, close_new_file, lock_file_name, probe_file_name
    implicit none
    private

    public :: manifest_type, manifest_file_name, is_own_name, is_state_name
    public :: is_bookkeeping_name, part_prefixes

    character(len=*), parameter :: manifest_file_name = '.yarnfort-manifest'

    !> The files of the folder's bookkeeping (never listed, never deleted): the manifest
    !> and its temporary, the lock and the write probe.
    character(len=*), parameter :: bookkeeping_names(*) = [character(len=22) :: &
        manifest_file_name, manifest_file_name // '.tmp', lock_file_name, probe_file_name]

    !> The fixed names a run may write (and their temporaries).
    character(len=*), parameter :: fixed_names(*) = [character(len=17) :: 'curve.csv', &
        'curve.csv.tmp', 'input.nml', 'input.nml.tmp', 'restart.dat', 'restart.dat.tmp', &
        'states.pvd', 'states.pvd.tmp', 'reactions.csv', 'reactions.csv.tmp', &
        'contacts.csv', 'contacts.csv.tmp', 'restart.sync', 'restart.sync.tmp']

    !> The blocks of a state besides the yarns' (state_NNNNN.vtu), by the prefix that
    !> replaces 'state_' in their file names (yarnfort_output_vtk): gap-holders,
    !> periodic links, sliding passages.
    character(len=*), parameter :: part_prefixes(3) = [character(len=9) :: 'holders_', &
        'links_', 'passages_']

    !> Longest file name kept (state names are far shorter).
    integer, parameter :: entry_length = 64

    type :: manifest_type
        character(len=:), allocatable :: folder
        !> Fixed files listed, and states with their step and pseudo-time (as loaded or
        !> saved: add_state keeps the states it adds apart until save or settle).
        character(len=entry_length), allocatable :: files(:), states(:)
        integer, allocatable :: steps(:)
        real(wp), allocatable :: times(:)
        integer :: unit = -1
        !> The states added since: the first n_added entries of arrays that grow by
        !> doubling, so that adding one costs constant time on average.
        character(len=entry_length), allocatable, private :: added_states(:)
        integer, allocatable, private :: added_steps(:)
        real(wp), allocatable, private :: added_times(:)
        integer, private :: n_added = 0
    contains
        !> Read folder's manifest (none: empty); `found` tells whether there was one.
        procedure :: load
        !> Replace the folder's manifest by this one, atomically, and keep it open for
        !> add_state.
        procedure :: save
        !> Append a state about to be written.
        procedure :: add_state
        !> Append a fixed name about to be written (once; saved first if not open).
        procedure :: add_file
        !> Whether a fixed name is listed (written by a run of ours).
        procedure :: has_file
        !> Move the states added since the last save into states, steps and times.
        procedure :: settle
        procedure :: close => close_manifest
    end type manifest_type

contains

    subroutine load(self, folder, found)
        class(manifest_type), intent(inout) :: self
        character(len=*), intent(in) :: folder
        logical, intent(out) :: found
        character(len=512) :: line
        character(len=16) :: kind
        character(len=entry_length) :: name
        integer :: unit, status, step
        real(wp) :: time

        call self%close()
        self%folder = folder
        allocate(character(len=entry_length) :: self%files(0), self%states(0))
        self%steps = [integer :: ]
        self%times = [real(wp) :: ]
        self%n_added = 0
        open(newunit=unit, file=folder // '/' // manifest_file_name, status='old', &
            action='read', iostat=status)
        found = status == 0
        if (.not. found) return
        do
            read(unit, '(a)', iostat=status) line
            if (status /= 0) exit
            read(line, *, iostat=status) kind, name
            if (status /= 0) cycle
            if (.not. is_own_name(name)) cycle
            select case (kind)
            case ('file')
                if (any(self%files == name)) cycle
                self%files = [self%files, name]
            case ('state')
                if (.not. is_state_name(name)) cycle
                read(line, *, iostat=status) kind, name, step, time
                ! A line cut short by a kill still names a file to delete.
                if (status /= 0) then
                    step = huge(step)
                    time = 0.0_wp
                end if
                call add_entry(self, name, step, time)
            end select
        end do
        close(unit)
        call self%settle()
    end subroutine load

    pure logical function has_file(self, name)
        class(manifest_type), intent(in) :: self
        character(len=*), intent(in) :: name
        has_file = .false.
        if (allocated(self%files)) has_file = any(self%files == name)
    end function has_file

    subroutine add_file(self, name, error)
        class(manifest_type), intent(inout) :: self
        character(len=*), intent(in) :: name
        type(error_type), allocatable, intent(out) :: error
        character(len=256) :: message
        integer :: status

        if (self%has_file(name)) return
        if (self%unit == -1) then
            call self%save(error)
            if (allocated(error)) return
        end if
        message = ''
        write(self%unit, '(a)', iostat=status, iomsg=message) 'file ' // name
        if (status /= 0) then
            call fatal_error(error, "cannot write '" // self%folder // '/' &
                // manifest_file_name // "': " // trim(message))
            return
        end if
        call flush_checked(self%unit, self%folder // '/' // manifest_file_name, error)
        if (allocated(error)) return
        self%files = [self%files, [character(len=entry_length) :: name]]
    end subroutine add_file

    subroutine save(self, error)
        class(manifest_type), intent(inout) :: self
        type(error_type), allocatable, intent(out) :: error
        type(error_type), allocatable :: ignored
        character(len=:), allocatable :: path, temporary
        character(len=256) :: message
        integer :: unit, status, i

        call self%close()
        call self%settle()
        path = self%folder // '/' // manifest_file_name
        temporary = path // '.tmp'
        call open_new_file(unit, temporary, error)
        if (allocated(error)) return
        status = 0
        message = ''
        do i = 1, size(self%files)
            if (status == 0) write(unit, '(a)', iostat=status, iomsg=message) &
                'file ' // trim(self%files(i))
        end do
        do i = 1, size(self%states)
            if (status == 0) call put_state(unit, self%states(i), self%steps(i), &
                self%times(i), status, message)
        end do
        call close_new_file(unit, temporary, error, status, message)
        if (allocated(error)) return
        call sync_file(temporary, error)
        if (.not. allocated(error)) call rename_file(temporary, path, error)
        if (allocated(error)) then
            call remove_file(temporary, ignored)
            return
        end if
        call open_append(self%unit, path, error)
    end subroutine save

    subroutine add_state(self, name, step, time, error)
        class(manifest_type), intent(inout) :: self
        character(len=*), intent(in) :: name
        integer, intent(in) :: step
        real(wp), intent(in) :: time
        type(error_type), allocatable, intent(out) :: error
        character(len=256) :: message
        integer :: status

        if (self%unit == -1) then
            call fatal_error(error, "'" // self%folder // '/' // manifest_file_name &
                // "' is not open")
            return
        end if
        call put_state(self%unit, name, step, time, &
            status, message)
        if (status /= 0) then
            call fatal_error(error, "cannot write '" // self%folder // '/' &
                // manifest_file_name // "': " // trim(message))
            return
        end if
        call flush_checked(self%unit, self%folder // '/' // manifest_file_name, error)
        if (allocated(error)) return
        call add_entry(self, name, step, time)
    end subroutine add_state

    !> Keep a state apart (settle moves it into the lists), doubling the room when full.
    subroutine add_entry(self, name, step, time)
        class(manifest_type), intent(inout) :: self
        character(len=*), intent(in) :: name
        integer, intent(in) :: step
        real(wp), intent(in) :: time
        character(len=entry_length), allocatable :: states(:)
        integer, allocatable :: steps(:)
        real(wp), allocatable :: times(:)
        integer :: room

        if (.not. allocated(self%added_states)) &
            allocate(self%added_states(16), self%added_steps(16), self%added_times(16))
        if (self%n_added == size(self%added_states)) then
            room = 2 * size(self%added_states)
            allocate(states(room), steps(room), times(room))
            states(:self%n_added) = self%added_states(:self%n_added)
            steps(:self%n_added) = self%added_steps(:self%n_added)
            times(:self%n_added) = self%added_times(:self%n_added)
            call move_alloc(states, self%added_states)
            call move_alloc(steps, self%added_steps)
            call move_alloc(times, self%added_times)
        end if
        self%n_added = self%n_added + 1
        self%added_states(self%n_added) = name
        self%added_steps(self%n_added) = step
        self%added_times(self%n_added) = time
    end subroutine add_entry

    subroutine settle(self)
        class(manifest_type), intent(inout) :: self

        if (self%n_added == 0) return
        self%states = [self%states, self%added_states(:self%n_added)]
        self%steps = [self%steps, self%added_steps(:self%n_added)]
        self%times = [self%times, self%added_times(:self%n_added)]
        self%n_added = 0
    end subroutine settle

    subroutine put_state(unit, name, step, time, status, message)
        integer, intent(in) :: unit
        character(len=*), intent(in) :: name
        integer, intent(in) :: step
        real(wp), intent(in) :: time
        integer, intent(out) :: status
        character(len=*), intent(inout) :: message
        write(unit, '("state ", a, 1x, i0, 1x, es24.16e3)', iostat=status, iomsg=message) &
            trim(name), step, time
    end subroutine put_state

    subroutine close_manifest(self)
        class(manifest_type), intent(inout) :: self
        integer :: status
        if (self%unit /= -1) close(self%unit, iostat=status)
        self%unit = -1
    end subroutine close_manifest

    !> A file of the folder's bookkeeping: the manifest, its temporary, the lock, the probe.
    pure logical function is_bookkeeping_name(name)
        character(len=*), intent(in) :: name
        is_bookkeeping_name = any(bookkeeping_names == name)
    end function is_bookkeeping_name

    !> A name this program writes into an output folder: a fixed name, a state file, its
    !> multiblock file (state_NNNNN.vtm) or one of its other blocks (holders_, links_,
    !> passages_ + the state's digits).
    pure logical function is_own_name(name)
        character(len=*), intent(in) :: name
        integer :: part, n
        is_own_name = any(fixed_names == name) .or. is_state_name(name)
        n = len(name)
        if (n > len('.vtm')) then
            if (name(n - 3:) == '.vtm') is_own_name = is_own_name &
                .or. is_state_name(name(:n - 4) // '.vtu')
        end if
        do part = 1, size(part_prefixes)
            n = len_trim(part_prefixes(part))
            if (len(name) <= n) cycle
            if (name(:n) == part_prefixes(part)(:n)) &
                is_own_name = is_own_name .or. is_state_name('state_' // name(n + 1:))
        end do
    end function is_own_name

    !> state_<at least 5 digits>.vtu
    pure logical function is_state_name(name)
        character(len=*), intent(in) :: name
        integer :: n
        n = len_trim(name)
        is_state_name = .false.
        if (n < len('state_00000.vtu')) return
        if (name(1:6) /= 'state_' .or. name(n - 3:n) /= '.vtu') return
        is_state_name = verify(name(7:n - 4), '0123456789') == 0
    end function is_state_name

end module yarnfort_output_manifest
