! SPDX-License-Identifier: MIT
!> The restart file, folder/restart.dat: the snapshot of the last converged step
!> (yarnfort_solver_restart), rewritten after every step. It is written to
!> restart.dat.tmp and renamed over restart.dat, so a run killed at any moment leaves
!> either the previous complete file or the new one (a kill loses no written data: no
!> fsync is needed for that). Flushing it to the device, which only a power cut or a
!> crash of the system needs, is the caller's choice per write (`sync`; see
!> docs/decisions.md, "restart.dat is flushed to disk by time, not by step"): the file
!> is fsync'ed before its rename, gets the second name restart.sync (a hard link, so
!> that the unflushed files renamed over restart.dat later leave it as it is), and the
!> folder is fsync'ed after the renames. After a power cut restart.sync is the restart
!> file of the last flush, whatever became of restart.dat.
!>
!> Binary (unformatted stream, native byte order, full precision), version 4:
!>     'yarnfort-restart' (16 characters), version (integer),
!>     input fingerprint (16 characters),
!>     n_nodes, n_elements, n_unknowns, n_passages, step, knot (integers),
!>     time, next_step, previous_load (reals), stepper (16 characters),
!>     n_channels (integer), load_old, time_old (reals), have_old (integer 0 or 1),
!>     factors(n_channels) (the load channels' factors), u(n_unknowns), u_old(n_unknowns),
!>     length0(n_elements),
!>     flow(n_passages), flow_old(n_passages) (reals), mode(n_passages) (integers),
!>     load_older (real), have_older, set_repeated (integers 0 or 1), u_older(n_unknowns),
!>     flow_older(n_passages) (reals),
!>     'end-of-restart' (16 characters), then the checksum of every byte before it
!>     (16 hex digits), so a file damaged after it was written is refused.
!> Integers are default integers (4 bytes), reals 8 bytes.
module yarnfort_output_restart_file
    use, intrinsic :: iso_fortran_env, only: int8, int64
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_text, only: string_type, format_integer, format_real, join_names
    use yarnfort_solver_restart, only: restart_type, stepper_elastic, stepper_friction
    use yarnfort_output_filesystem, only: rename_file, remove_file, sync_file, sync_folder, &
        link_file, close_checked, open_new_file, close_new_file
    implicit none
    private

    public :: restart_file_name, write_restart, read_restart, check_restart
    public :: remove_restart, get_input_hash, sync_restart, synced_file_name

    character(len=*), parameter :: restart_file_name = 'restart.dat'
    !> The restart file of the last flush to disk (sync_restart, write_restart's `sync`).
    character(len=*), parameter :: synced_file_name = 'restart.sync'
    character(len=16), parameter :: magic = 'yarnfort-restart'
    character(len=16), parameter :: end_marker = 'end-of-restart'
    !> Version 5 added the force-control slopes (held_slope) before the end marker; a
    !> version 4 file, without them, is read with slopes 0 (its restart agrees with the
    !> uninterrupted run to the outer iteration's tolerance, not bit for bit).
    integer, parameter :: format_version = 5, oldest_version = 4
    !> Most load channels a restart file may hold (&path channels has at most 8).
    integer, parameter :: max_restart_channels = 64

    !> Two 32-bit multiplicative hashes of the FNV-1a kind (FNV's offset basis and prime,
    !> and a second basis and prime) make the 64-bit fingerprint. Values stay below
    !> 2**32 in 64-bit integers, so the products never overflow.
    integer(int64), parameter :: hash_prime(2) = [16777619_int64, 1000003_int64]
    integer(int64), parameter :: hash_basis(2) = [2166136261_int64, 3735928559_int64]
    integer(int64), parameter :: two_32 = 4294967296_int64

    !> Pseudo-times closer than this, relative to the path's length, are the same knot
    !> (the continuation's rule).
    real(wp), parameter :: knot_tolerance = 1.0e-12_wp
    !> Load factors of a restart file and of the path at its time may differ by this,
    !> relative to the path's largest factor (they are computed the same way).
    real(wp), parameter :: factor_tolerance = 64 * epsilon(1.0_wp)
    !> Echo lines of variables added after restart files were first written, at their
    !> defaults: left out of the fingerprint, so that a restart file of an input without
    !> them stays valid (one that sets them is another input).
    character(len=*), parameter :: unhashed_defaults(6) = [character(len=32) :: &
        "    lateral_control = 'strain'", '    lateral_force = 0.0', '    force_ratio = 1.0', &
        "    axial_control = 'strain'", '    axial_force = 0.0', '    shear = 0.0']
    !> Bytes read at a time when an input file's content is hashed.
    integer, parameter :: hash_chunk = 65536

contains

    !> Write `snapshot` (stamped with `input_hash`) to folder/restart.dat atomically;
    !> with `sync` (default true) also flushed to the device before it replaces the
    !> previous file, kept as restart.sync too, and the renames flushed after it.
    subroutine write_restart(folder, snapshot, input_hash, error, sync)
        character(len=*), intent(in) :: folder
        type(restart_type), intent(in) :: snapshot
        character(len=*), intent(in) :: input_hash
        type(error_type), allocatable, intent(out) :: error
        logical, intent(in), optional :: sync
        character(len=:), allocatable :: path, temporary
        character(len=16) :: stamp, stepper
        character(len=256) :: message
        type(error_type), allocatable :: ignored
        integer :: unit, status
        logical :: flush_now

        path = folder // '/' // restart_file_name
        temporary = path // '.tmp'
        call open_new_file(unit, temporary, error, stream=.true.)
        if (allocated(error)) return
        message = ''
        stamp = input_hash
        stepper = snapshot%stepper
        associate(s => snapshot)
            write(unit, iostat=status, iomsg=message) magic, format_version, stamp, &
                s%n_nodes, s%n_elements, &
                s%n_unknowns, s%n_passages, s%step, s%knot, s%time, s%next_step, &
                s%previous_load, stepper, size(s%factors), s%load_old, s%time_old, &
                merge(1, 0, s%have_old)
            if (status == 0) write(unit, iostat=status, iomsg=message) s%factors
            if (status == 0) call put_reals(s%u, s%n_unknowns)
            if (status == 0) call put_reals(s%u_old, s%n_unknowns)
            if (status == 0) call put_reals(s%length0, s%n_elements)
            if (status == 0) call put_reals(s%flow, s%n_passages)
            if (status == 0) call put_reals(s%flow_old, s%n_passages)
            if (status == 0) then
                if (allocated(s%mode)) then
                    write(unit, iostat=status, iomsg=message) s%mode
                else
                    write(unit, iostat=status, iomsg=message) [integer :: ]
                end if
            end if
            if (status == 0) write(unit, iostat=status, iomsg=message) s%load_older, &
                merge(1, 0, s%have_older), merge(1, 0, s%set_repeated)
            if (status == 0) call put_reals(s%u_older, s%n_unknowns)
            if (status == 0) call put_reals(s%flow_older, s%n_passages)
            if (status == 0) write(unit, iostat=status, iomsg=message) s%held_slope
            if (status == 0) write(unit, iostat=status, iomsg=message) end_marker
        end associate
        call close_new_file(unit, temporary, error, status, message)
        if (.not. allocated(error)) call append_checksum(temporary, error)
        if (allocated(error)) then
            call remove_file(temporary, ignored)
            error%message = error%message // kept()
            return
        end if
        if (present(sync)) then
            flush_now = sync
        else
            flush_now = .true.
        end if
        ! On disk before it replaces the previous file: a crash of the machine cannot
        ! leave an empty restart file behind.
        if (flush_now) call sync_file(temporary, error)
        if (flush_now .and. .not. allocated(error)) call keep_synced(folder, temporary, error)
        if (.not. allocated(error)) call rename_file(temporary, path, error)
        if (allocated(error)) then
            call remove_file(temporary, ignored)
            return
        end if
        ! The folder holds the rename: on disk too, or a crash may bring back the old file.
        if (flush_now) call sync_folder(folder, error)
    contains
        !> What the failure leaves: the previous restart file, if there is one.
        function kept() result(text)
            character(len=:), allocatable :: text
            logical :: exists
            inquire(file=path, exist=exists)
            text = ''
            if (exists) text = " (the previous '" // path // "' is kept)"
        end function kept

        !> The array, or zeros when the snapshot has none (e.g. no previous state).
        subroutine put_reals(values, n)
            real(wp), allocatable, intent(in) :: values(:)
            integer, intent(in) :: n
            if (allocated(values)) then
                if (size(values) == n) then
                    write(unit, iostat=status, iomsg=message) values
                    return
                end if
            end if
            write(unit, iostat=status, iomsg=message) spread(0.0_wp, 1, n)
        end subroutine put_reals
    end subroutine write_restart

    !> Read folder/restart.dat (or folder/`name`) into `snapshot`. The error says whether
    !> the file is missing, not a restart file, of another version, cut short or too
    !> long, or holds sizes that do not fit its length (checked before anything is
    !> allocated, so a damaged size field cannot ask for memory).
    subroutine read_restart(folder, snapshot, error, name)
        character(len=*), intent(in) :: folder
        type(restart_type), intent(out) :: snapshot
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in), optional :: name
        character(len=:), allocatable :: path
        character(len=16) :: header, marker, checksum
        character(len=32) :: text
        character(len=256) :: message
        integer :: unit, status, version, have_old, n_channels, have_older, set_repeated
        integer(int64) :: file_size, position, expected
        logical :: exists

        path = folder // '/' // restart_file_name
        if (present(name)) path = folder // '/' // name
        inquire(file=path, exist=exists)
        if (.not. exists) then
            call fatal_error(error, "&control restart: no restart file '" // path &
                // "' (a run writes it after every converged step; set restart = .false. " &
                // "to start from the beginning)")
            return
        end if
        message = ''
        open(newunit=unit, file=path, access='stream', form='unformatted', status='old', &
            action='read', iostat=status, iomsg=message)
        if (status /= 0) then
            call fatal_error(error, "&control restart: cannot read '" // path // "': " &
                // trim(message))
            return
        end if
        read(unit, iostat=status) header
        if (status /= 0 .or. header /= magic) then
            close(unit)
            call fatal_error(error, "&control restart: '" // path &
                // "' is not a yarnfort restart file")
            return
        end if
        read(unit, iostat=status) version
        if (status /= 0 .or. version < oldest_version .or. version > format_version) then
            close(unit)
            write(text, '(i0)') version
            call fatal_error(error, "&control restart: '" // path // "' has format version " &
                // trim(text) // ', this yarnfort reads versions ' &
                // format_integer(oldest_version) // ' to ' // format_integer(format_version))
            return
        end if
        associate(s => snapshot)
            read(unit, iostat=status) s%input_hash, s%n_nodes, s%n_elements, s%n_unknowns, &
                s%n_passages, s%step, s%knot, s%time, s%next_step, s%previous_load, &
                s%stepper, n_channels, s%load_old, s%time_old, have_old
            if (status /= 0) then
                close(unit)
                call fatal_error(error, "&control restart: '" // path &
                    // "' is cut short or unreadable")
                return
            end if
            if (min(s%n_nodes, s%n_elements, s%n_unknowns, s%n_passages) < 0 .or. &
                    (have_old /= 0 .and. have_old /= 1) .or. n_channels < 1 .or. &
                    n_channels > max_restart_channels) then
                close(unit)
                call fatal_error(error, "&control restart: '" // path // "' is damaged: " &
                    // 'a size or flag field holds an impossible value')
                return
            end if
            ! What follows must be exactly the arrays of these sizes and the end marker.
            inquire(unit=unit, size=file_size, pos=position)
            expected = 8_int64 * (n_channels + 3_int64 * s%n_unknowns + s%n_elements &
                + 3_int64 * s%n_passages + 1 + merge(2, 0, version >= 5)) &
                + 4_int64 * (s%n_passages + 2) + len(end_marker) + len(checksum)
            if (file_size - (position - 1) /= expected) then
                close(unit)
                write(text, '(i0)') file_size
                call fatal_error(error, "&control restart: '" // path // "' is cut short " &
                    // 'or unreadable: its ' // trim(text) // ' bytes do not fit the sizes ' &
                    // 'it records')
                return
            end if
            s%have_old = have_old /= 0
            allocate(s%factors(n_channels), s%u(s%n_unknowns), s%u_old(s%n_unknowns), &
                s%length0(s%n_elements), &
                s%flow(s%n_passages), s%flow_old(s%n_passages), s%mode(s%n_passages), &
                s%u_older(s%n_unknowns), s%flow_older(s%n_passages), &
                stat=status, errmsg=message)
            if (status /= 0) then
                close(unit)
                call fatal_error(error, "&control restart: not enough memory to read '" &
                    // path // "': " // trim(message))
                return
            end if
            read(unit, iostat=status) s%factors, s%u, s%u_old, s%length0, s%flow, &
                s%flow_old, s%mode, s%load_older, have_older, set_repeated, s%u_older, &
                s%flow_older
            if (status == 0 .and. version >= 5) read(unit, iostat=status) s%held_slope
            if (status == 0) read(unit, iostat=status) marker, checksum
            if (status == 0 .and. marker /= end_marker) status = -1
            s%have_older = have_older == 1
            s%set_repeated = set_repeated == 1
            if (status == 0 .and. (have_older /= 0 .and. have_older /= 1 &
                    .or. set_repeated /= 0 .and. set_repeated /= 1)) then
                close(unit)
                call fatal_error(error, "&control restart: '" // path // "' is damaged: " &
                    // 'a size or flag field holds an impossible value')
                return
            end if
        end associate
        close(unit)
        if (status /= 0) then
            call fatal_error(error, "&control restart: '" // path &
                // "' is cut short or unreadable")
            return
        end if
        if (get_checksum(path, file_size - len(checksum)) /= checksum) then
            call fatal_error(error, "&control restart: '" // path // "' is damaged: its " &
                // 'checksum does not match its content')
            return
        end if
    end subroutine read_restart

    !> Fail unless `snapshot` was written for this scene and its path: the same sizes,
    !> the same input fingerprint (`input_hash`, from get_input_hash), the stepper of the
    !> scene, and fields that a run of this scene can have written: a step >= 0, a time
    !> on the path with the knot it heads for, a next step size in [min_step, max_step], the
    !> load factors of the path at that time, finite unknowns and flows, positive
    !> reference lengths and known passage modes.
    subroutine check_restart(snapshot, scene, input_hash, folder, error)
        type(restart_type), intent(in) :: snapshot
        type(scene_type), intent(in) :: scene
        character(len=*), intent(in) :: input_hash, folder
        type(error_type), allocatable, intent(out) :: error
        character(len=200) :: file_sizes, scene_sizes
        character(len=:), allocatable :: path, expected_stepper
        real(wp) :: t_start, t_end, span, scale
        real(wp), allocatable :: factors(:)
        integer :: n_knots, c
        integer :: control(2)

        ! The channels of force-controlled periods (0: none).
        control = [scene%axial_channel, scene%lateral_channel]
        path = folder // '/' // restart_file_name
        write(file_sizes, '(i0, " nodes, ", i0, " elements, ", i0, " unknowns, ", i0, &
            & " passages")') snapshot%n_nodes, snapshot%n_elements, snapshot%n_unknowns, &
            snapshot%n_passages
        write(scene_sizes, '(i0, " nodes, ", i0, " elements, ", i0, " unknowns, ", i0, &
            & " passages")') scene%network%n_nodes(), scene%network%n_elements(), &
            scene%dofs%n_unknowns, scene%passages%size()
        if (file_sizes /= scene_sizes) then
            call fatal_error(error, "&control restart: '" // path // "' does not match " &
                // 'the scene: it has ' // trim(file_sizes) // ', the scene has ' &
                // trim(scene_sizes))
            return
        end if
        if (snapshot%input_hash /= input_hash) then
            call fatal_error(error, "&control restart: '" // path // "' was written for " &
                // 'another input (fingerprint ' // trim(snapshot%input_hash) // ', this ' &
                // 'input ' // trim(input_hash) // '); only &control and &output may change ' &
                // 'between a run and its restart')
            return
        end if
        expected_stepper = stepper_elastic
        if (scene%passages%size() > 0) expected_stepper = stepper_friction
        if (trim(snapshot%stepper) /= expected_stepper) then
            call damaged("its stepper '" // trim(snapshot%stepper) // "' is not '" &
                // expected_stepper // "', that of this scene")
            return
        end if
        if (snapshot%step < 0) then
            call damaged('step ' // format_integer(snapshot%step) // ' is negative')
            return
        end if
        associate(knots => scene%path%time)
            n_knots = size(knots)
            t_start = knots(1)
            t_end = knots(n_knots)
            span = t_end - t_start
            if (.not. (snapshot%time >= t_start .and. snapshot%time <= t_end)) then
                call damaged('time ' // format_real(snapshot%time) // ' is not on ' &
                    // 'the load path (' // format_real(t_start) // ' to ' &
                    // format_real(t_end) // ')')
                return
            end if
            if (snapshot%knot < 2 .or. snapshot%knot > n_knots) then
                call damaged('knot ' // format_integer(snapshot%knot) // ' is not 2..' &
                    // format_integer(n_knots))
                return
            end if
            if (knots(snapshot%knot - 1) > snapshot%time + knot_tolerance * span .or. &
                    knots(snapshot%knot) < snapshot%time - knot_tolerance * span) then
                call damaged('time ' // format_real(snapshot%time) // ' is not ' &
                    // 'before knot ' // format_integer(snapshot%knot) &
                    // ', the knot it heads for')
                return
            end if
        end associate
        if (.not. (snapshot%next_step >= scene%solver%min_step .and. &
                snapshot%next_step <= scene%solver%max_step)) then
            call damaged('next step ' // format_real(snapshot%next_step) &
                // ' is not in [min_step = ' // format_real(scene%solver%min_step) &
                // ', max_step = ' // format_real(scene%solver%max_step) // ']')
            return
        end if
        ! The run computed these factors from the same time by the same code: they agree
        ! to round-off of the path's own factors.
        if (size(snapshot%factors) /= scene%path%n_channels()) then
            call damaged('it has ' // format_integer(size(snapshot%factors)) // ' load ' &
                // 'channels, the scene ' // format_integer(scene%path%n_channels()))
            return
        end if
        allocate(factors(scene%path%n_channels()))
        call scene%path%get_factors(snapshot%time, factors)
        scale = max(maxval(abs(scene%path%factor)), tiny(1.0_wp))
        ! A force-controlled period: its channel's factor is the strain found, not the
        ! path's.
        if (size(snapshot%factors) == size(factors)) then
            do c = 1, size(control)
                if (control(c) == 0) cycle
                if (abs(snapshot%factors(control(c))) <= 100.0_wp) &
                    factors(control(c)) = snapshot%factors(control(c))
            end do
        end if
        if (.not. all(abs(snapshot%factors - factors) <= factor_tolerance * scale)) then
            call damaged('its load factors ' // join_reals(snapshot%factors) // ' are not ' &
                // 'those of the path at its time (' // join_reals(factors) // ') for the ' &
                // 'channels ' // join_names(scene%path%channel, ''))
            return
        end if
        ! The continuation's load is the path's (the control channels' factors 0 there).
        do c = 1, size(control)
            if (control(c) > 0) factors(control(c)) = 0.0_wp
        end do
        if (.not. abs(snapshot%previous_load - sum(factors)) <= factor_tolerance &
                * size(factors) * scale) then
            call damaged('its previous load ' // format_real(snapshot%previous_load) &
                // ' is not the sum of its load factors')
            return
        end if
        if (.not. finite_state(snapshot%previous_load, snapshot%u, snapshot%flow)) then
            call damaged('it holds a position or flow that is not a finite number')
            return
        end if
        ! A secant slope is kept only when positive (a stretched period pulls harder).
        if (.not. all(snapshot%held_slope >= 0.0_wp .and. ieee_is_finite(snapshot%held_slope))) then
            call damaged('it holds a force-control slope that is not a number >= 0')
            return
        end if
        if (.not. all(snapshot%length0 > 0.0_wp .and. ieee_is_finite(snapshot%length0))) then
            call damaged('it holds a reference length that is not a positive number')
            return
        end if
        if (.not. all(abs(snapshot%mode) <= 1)) then
            call damaged('it holds an unknown passage mode')
            return
        end if
        if (snapshot%have_old) then
            if (.not. finite_state(snapshot%load_old, snapshot%u_old, snapshot%flow_old)) then
                call damaged('its previous state holds a value that is not a finite number')
                return
            end if
            if (snapshot%have_older) then
                if (.not. finite_state(snapshot%load_older, snapshot%u_older, &
                        snapshot%flow_older)) then
                    call damaged('its state before the previous one holds a value that is ' &
                        // 'not a finite number')
                    return
                end if
            end if
            ! After step 0 the previous state is the step before: its time lies on the
            ! path before this one (and is its curve row's, checked with curve.csv), and
            ! its load is the path's there.
            if (snapshot%step > 0) then
                if (.not. (snapshot%time_old >= scene%path%time(1) .and. &
                        snapshot%time_old < snapshot%time)) then
                    call damaged('the time ' // format_real(snapshot%time_old) // ' of its ' &
                        // 'previous step is not on the load path before its time ' &
                        // format_real(snapshot%time))
                    return
                end if
                call scene%path%get_factors(snapshot%time_old, factors)
                ! (Unknown under force control: it holds the previous step's strain.)
                if (all(control == 0) .and. .not. abs(snapshot%load_old &
                        - sum(factors)) <= factor_tolerance * size(factors) * scale) then
                    call damaged('the load ' // format_real(snapshot%load_old) // ' of its ' &
                        // 'previous step is not the sum of the load factors at its time ' &
                        // format_real(snapshot%time_old))
                    return
                end if
            end if
        end if
    contains
        function join_reals(values) result(text)
            real(wp), intent(in) :: values(:)
            character(len=:), allocatable :: text
            integer :: i
            text = ''
            do i = 1, size(values)
                if (i > 1) text = text // ', '
                text = text // format_real(values(i))
            end do
        end function join_reals

        subroutine damaged(reason)
            character(len=*), intent(in) :: reason
            call fatal_error(error, "&control restart: '" // path // "' is damaged or not " &
                // 'of this scene: ' // reason)
        end subroutine damaged

        !> The load, every position (u) and every flow of a stored state are finite numbers.
        pure logical function finite_state(load, u, flow)
            real(wp), intent(in) :: load, u(:), flow(:)
            finite_state = ieee_is_finite(load) .and. all(ieee_is_finite(u)) &
                .and. all(ieee_is_finite(flow))
        end function finite_state
    end subroutine check_restart

    !> Flush folder/restart.dat, written without `sync`, to the device, keep it as
    !> restart.sync too, and flush the folder (which holds the renames). No restart file
    !> is fine (no step converged).
    subroutine sync_restart(folder, error)
        character(len=*), intent(in) :: folder
        type(error_type), allocatable, intent(out) :: error
        character(len=:), allocatable :: path
        logical :: exists

        path = folder // '/' // restart_file_name
        inquire(file=path, exist=exists)
        if (exists) call sync_file(path, error)
        if (exists .and. .not. allocated(error)) call keep_synced(folder, path, error)
        if (.not. allocated(error)) call sync_folder(folder, error)
    end subroutine sync_restart

    !> Give the flushed restart file `path` the name folder/restart.sync, atomically
    !> (a link under restart.sync.tmp renamed over it). A file system without hard links
    !> keeps the restart.sync of earlier flushes, if any (still one the tables hold).
    subroutine keep_synced(folder, path, error)
        character(len=*), intent(in) :: folder, path
        type(error_type), allocatable, intent(out) :: error
        character(len=:), allocatable :: synced
        logical :: linked

        synced = folder // '/' // synced_file_name
        ! A link left by a kill would make link() fail.
        call remove_file(synced // '.tmp', error)
        if (.not. allocated(error)) call link_file(path, synced // '.tmp', error, linked)
        if (.not. allocated(error) .and. linked) call rename_file(synced // '.tmp', synced, &
            error)
    end subroutine keep_synced

    !> Delete folder/restart.dat and folder/restart.sync, each if it is a yarnfort
    !> restart file (a new run starts from the beginning); any other file of those names
    !> is left alone.
    subroutine remove_restart(folder)
        character(len=*), intent(in) :: folder
        type(error_type), allocatable :: ignored
        character(len=16) :: header
        integer :: unit, status, i
        character(len=*), parameter :: names(2) = [character(len=len(restart_file_name)) &
            :: restart_file_name, synced_file_name]

        do i = 1, size(names)
            open(newunit=unit, file=folder // '/' // trim(names(i)), status='old', &
                access='stream', form='unformatted', action='read', iostat=status)
            if (status /= 0) cycle
            read(unit, iostat=status) header
            close(unit)
            ! (A regular file only: a link of that name is left alone.)
            if (status == 0 .and. header == magic) &
                call remove_file(folder // '/' // trim(names(i)), ignored)
        end do
    end subroutine remove_restart

    !> Fingerprint (16 hex digits) of what determines a run's path: `echo`, the lines of
    !> the effective input's echo without &control and &output and without the input
    !> folder (the caller renders it: output/ does not read the input), the content of
    !> the files it names (`files`, resolved paths in the input's order: material
    !> tables, contact rate tables, the geometry file), and the built scene's node
    !> positions, elements, reference lengths, external forces and load path.
    function get_input_hash(echo, files, scene) result(hash)
        type(string_type), intent(in) :: echo(:), files(:)
        type(scene_type), intent(in) :: scene
        character(len=16) :: hash
        integer(int64) :: state(2)
        integer :: i

        state = hash_basis
        do i = 1, size(echo)
            if (any(echo(i)%text == unhashed_defaults)) cycle
            call add_bytes(transfer(echo(i)%text, [0_int8], len(echo(i)%text)))
            call add_bytes([10_int8])
        end do
        do i = 1, size(files)
            call add_file_bytes(state, files(i)%text)
        end do
        call add_bytes(transfer(scene%network%position, [0_int8]))
        call add_bytes(transfer(scene%network%element_nodes, [0_int8]))
        call add_bytes(transfer(scene%network%length0, [0_int8]))
        call add_bytes(transfer(scene%external_force, [0_int8]))
        call add_bytes(transfer(scene%path%time, [0_int8]))
        call add_bytes(transfer(scene%path%factor, [0_int8]))
        call add_bytes(transfer(scene%path%channel, [0_int8]))
        call add_bytes(transfer(scene%dofs%delta, [0_int8]))
        write(hash, '(z8.8, z8.8)') state(1), state(2)
    contains
        subroutine add_bytes(bytes)
            integer(int8), intent(in) :: bytes(:)
            call add_hash_bytes(state, bytes)
        end subroutine add_bytes
    end function get_input_hash

    !> Add `bytes` to the two 32-bit FNV-1a-like hashes of `state`.
    pure subroutine add_hash_bytes(state, bytes)
        integer(int64), intent(inout) :: state(2)
        integer(int8), intent(in) :: bytes(:)
        integer :: i
        do i = 1, size(bytes)
            state = mod(ieor(state, iand(int(bytes(i), int64), 255_int64)) * hash_prime, two_32)
        end do
    end subroutine add_hash_bytes

    !> Add the bytes of a file (its first `limit` bytes if given), then their count; an
    !> unreadable file adds a marker (its hash then differs from that of any content).
    subroutine add_file_bytes(state, path, limit)
        integer(int64), intent(inout) :: state(2)
        character(len=*), intent(in) :: path
        integer(int64), intent(in), optional :: limit
        integer(int8) :: bytes(hash_chunk)
        integer(int64) :: file_size, done
        integer :: file, stat, n

        open(newunit=file, file=path, access='stream', form='unformatted', &
            status='old', action='read', iostat=stat)
        if (stat /= 0) then
            call add_hash_bytes(state, transfer('unreadable file', [0_int8]))
            return
        end if
        inquire(unit=file, size=file_size)
        if (present(limit)) file_size = min(file_size, limit)
        done = 0
        do while (done < file_size)
            n = int(min(int(hash_chunk, int64), file_size - done))
            read(file, iostat=stat) bytes(:n)
            if (stat /= 0) then
                call add_hash_bytes(state, transfer('unreadable file', [0_int8]))
                exit
            end if
            call add_hash_bytes(state, bytes(:n))
            done = done + n
        end do
        close(file)
        call add_hash_bytes(state, transfer(file_size, [0_int8]))
    end subroutine add_file_bytes

    !> Append to the restart file `path` (closed, complete up to its end marker) the
    !> checksum of its bytes.
    subroutine append_checksum(path, error)
        character(len=*), intent(in) :: path
        type(error_type), allocatable, intent(out) :: error
        character(len=16) :: digest
        character(len=256) :: message
        integer :: unit, status

        digest = get_checksum(path)
        message = ''
        open(newunit=unit, file=path, access='stream', form='unformatted', status='old', &
            position='append', action='write', iostat=status, iomsg=message)
        if (status == 0) write(unit, iostat=status, iomsg=message) digest
        if (status /= 0) then
            call fatal_error(error, "cannot write '" // path // "': " // trim(message))
            return
        end if
        call close_checked(unit, path, error)
    end subroutine append_checksum

    !> The checksum (16 hex digits) of the file `path`, or of its first `limit` bytes.
    function get_checksum(path, limit) result(digest)
        character(len=*), intent(in) :: path
        integer(int64), intent(in), optional :: limit
        character(len=16) :: digest
        integer(int64) :: state(2)

        state = hash_basis
        call add_file_bytes(state, path, limit)
        write(digest, '(z8.8, z8.8)') state(1), state(2)
    end function get_checksum

end module yarnfort_output_restart_file
