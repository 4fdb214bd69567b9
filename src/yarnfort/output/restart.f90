! SPDX-License-Identifier: MIT
!> The restart file, folder/restart.dat: the snapshot of the last converged step
!> (yarnfort_solver_restart), rewritten after every step. It is written to
!> restart.dat.tmp and renamed over restart.dat, so a run killed at any moment leaves
!> either the previous complete file or the new one.
!>
!> Binary (unformatted stream, native byte order, full precision), version 1:
!>     'yarnfort-restart' (16 characters), version (integer),
!>     input fingerprint (16 characters),
!>     n_nodes, n_elements, n_unknowns, n_passages, step, knot (integers),
!>     time, next_step, previous_load (reals), stepper (16 characters),
!>     p_force, p_disp, load_old (reals), have_old (integer 0 or 1),
!>     u(n_unknowns), u_old(n_unknowns), length0(n_elements),
!>     flow(n_passages), flow_old(n_passages) (reals), mode(n_passages) (integers),
!>     'end-of-restart' (16 characters).
!> Integers are default integers (4 bytes), reals 8 bytes.
module yarnfort_output_restart
    use, intrinsic :: iso_fortran_env, only: int8, int64
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_input_config, only: config_type, control_config_type, output_config_type
    use yarnfort_input_echo, only: write_config
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_solver_restart, only: restart_type
    use yarnfort_output_filesystem, only: rename_file
    implicit none
    private

    public :: restart_file_name, write_restart, read_restart, check_restart
    public :: remove_restart, get_input_hash

    character(len=*), parameter :: restart_file_name = 'restart.dat'
    character(len=16), parameter :: magic = 'yarnfort-restart'
    character(len=16), parameter :: end_marker = 'end-of-restart'
    integer, parameter :: format_version = 1

    !> Two 32-bit multiplicative hashes of the FNV-1a kind (FNV's offset basis and prime,
    !> and a second basis and prime) make the 64-bit fingerprint. Values stay below
    !> 2**32 in 64-bit integers, so the products never overflow.
    integer(int64), parameter :: hash_prime(2) = [16777619_int64, 1000003_int64]
    integer(int64), parameter :: hash_basis(2) = [2166136261_int64, 3735928559_int64]
    integer(int64), parameter :: two_32 = 4294967296_int64

contains

    !> Write `snapshot` (stamped with `input_hash`) to folder/restart.dat atomically.
    subroutine write_restart(folder, snapshot, input_hash, error)
        character(len=*), intent(in) :: folder
        type(restart_type), intent(in) :: snapshot
        character(len=*), intent(in) :: input_hash
        type(error_type), allocatable, intent(out) :: error
        character(len=:), allocatable :: path, temporary
        character(len=16) :: stamp, stepper
        integer :: unit, status

        path = folder // '/' // restart_file_name
        temporary = path // '.tmp'
        open(newunit=unit, file=temporary, access='stream', form='unformatted', &
            status='replace', action='write', iostat=status)
        if (status /= 0) then
            call fatal_error(error, "cannot write '" // temporary // "'")
            return
        end if
        stamp = input_hash
        stepper = snapshot%stepper
        associate(s => snapshot)
            write(unit, iostat=status) magic, format_version, stamp, s%n_nodes, s%n_elements, &
                s%n_unknowns, s%n_passages, s%step, s%knot, s%time, s%next_step, &
                s%previous_load, stepper, s%p_force, s%p_disp, s%load_old, &
                merge(1, 0, s%have_old)
            if (status == 0) call put_reals(s%u, s%n_unknowns)
            if (status == 0) call put_reals(s%u_old, s%n_unknowns)
            if (status == 0) call put_reals(s%length0, s%n_elements)
            if (status == 0) call put_reals(s%flow, s%n_passages)
            if (status == 0) call put_reals(s%flow_old, s%n_passages)
            if (status == 0) then
                if (allocated(s%mode)) then
                    write(unit, iostat=status) s%mode
                else
                    write(unit, iostat=status) [integer :: ]
                end if
            end if
            if (status == 0) write(unit, iostat=status) end_marker
        end associate
        if (status /= 0) then
            close(unit, status='delete')
            call fatal_error(error, "cannot write '" // temporary // "'")
            return
        end if
        close(unit, iostat=status)
        if (status /= 0) then
            call fatal_error(error, "cannot write '" // temporary // "'")
            return
        end if
        call rename_file(temporary, path, error)
    contains
        !> The array, or zeros when the snapshot has none (e.g. no previous state).
        subroutine put_reals(values, n)
            real(wp), allocatable, intent(in) :: values(:)
            integer, intent(in) :: n
            if (allocated(values)) then
                if (size(values) == n) then
                    write(unit, iostat=status) values
                    return
                end if
            end if
            write(unit, iostat=status) spread(0.0_wp, 1, n)
        end subroutine put_reals
    end subroutine write_restart

    !> Read folder/restart.dat into `snapshot`. The error says whether the file is
    !> missing, not a restart file, of another version, or cut short.
    subroutine read_restart(folder, snapshot, error)
        character(len=*), intent(in) :: folder
        type(restart_type), intent(out) :: snapshot
        type(error_type), allocatable, intent(out) :: error
        character(len=:), allocatable :: path
        character(len=16) :: header, marker
        character(len=32) :: text
        integer :: unit, status, version, have_old
        logical :: exists

        path = folder // '/' // restart_file_name
        inquire(file=path, exist=exists)
        if (.not. exists) then
            call fatal_error(error, "&control restart: no restart file '" // path &
                // "' (a run writes it after every converged step; set restart = .false. " &
                // "to start from the beginning)")
            return
        end if
        open(newunit=unit, file=path, access='stream', form='unformatted', status='old', &
            action='read', iostat=status)
        if (status /= 0) then
            call fatal_error(error, "&control restart: cannot read '" // path // "'")
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
        if (status /= 0 .or. version /= format_version) then
            close(unit)
            write(text, '(i0)') version
            call fatal_error(error, "&control restart: '" // path // "' has format version " &
                // trim(text) // ', this yarnfort reads version 1')
            return
        end if
        associate(s => snapshot)
            read(unit, iostat=status) s%input_hash, s%n_nodes, s%n_elements, s%n_unknowns, &
                s%n_passages, s%step, s%knot, s%time, s%next_step, s%previous_load, &
                s%stepper, s%p_force, s%p_disp, s%load_old, have_old
            if (status == 0 .and. min(s%n_nodes, s%n_elements, s%n_unknowns, &
                    s%n_passages) < 0) status = -1
            if (status == 0) then
                s%have_old = have_old /= 0
                allocate(s%u(s%n_unknowns), s%u_old(s%n_unknowns), s%length0(s%n_elements))
                allocate(s%flow(s%n_passages), s%flow_old(s%n_passages), s%mode(s%n_passages))
                read(unit, iostat=status) s%u, s%u_old, s%length0, s%flow, s%flow_old, s%mode, &
                    marker
            end if
            if (status == 0 .and. marker /= end_marker) status = -1
        end associate
        close(unit)
        if (status /= 0) then
            call fatal_error(error, "&control restart: '" // path &
                // "' is cut short or unreadable")
            return
        end if
    end subroutine read_restart

    !> Fail unless `snapshot` was written for this scene: the same sizes and the same
    !> input fingerprint (`input_hash`, from get_input_hash).
    subroutine check_restart(snapshot, scene, input_hash, folder, error)
        type(restart_type), intent(in) :: snapshot
        type(scene_type), intent(in) :: scene
        character(len=*), intent(in) :: input_hash, folder
        type(error_type), allocatable, intent(out) :: error
        character(len=200) :: file_sizes, scene_sizes
        character(len=:), allocatable :: path

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
    end subroutine check_restart

    !> Delete folder/restart.dat if there is one (a new run starts from the beginning).
    subroutine remove_restart(folder)
        character(len=*), intent(in) :: folder
        integer :: unit, status

        open(newunit=unit, file=folder // '/' // restart_file_name, status='old', &
            iostat=status)
        if (status == 0) close(unit, status='delete')
    end subroutine remove_restart

    !> Fingerprint (16 hex digits) of what determines a run's path: the effective input
    !> without &control and &output (as written by write_config), and the built scene's
    !> node positions, elements, reference lengths, external forces and load path (which
    !> also covers the contents of a geometry file).
    function get_input_hash(config, scene) result(hash)
        type(config_type), intent(in) :: config
        type(scene_type), intent(in) :: scene
        character(len=16) :: hash
        type(config_type) :: copy
        integer(int64) :: state(2)
        character(len=1024) :: chunk
        integer :: unit, status, n

        state = hash_basis
        copy = config
        copy%control = control_config_type()
        copy%output = output_config_type()
        copy%input_folder = ''
        open(newunit=unit, status='scratch', form='formatted', action='readwrite', &
            iostat=status)
        if (status == 0) then
            call write_config(unit, copy)
            rewind(unit)
            do
                read(unit, '(a)', advance='no', size=n, iostat=status) chunk
                if (is_iostat_end(status)) exit
                if (status /= 0 .and. .not. is_iostat_eor(status)) exit
                call add_bytes(transfer(chunk(:n), [0_int8], n))
                if (is_iostat_eor(status)) call add_bytes([10_int8])
            end do
            close(unit)
        end if
        call add_bytes(transfer(scene%network%position, [0_int8]))
        call add_bytes(transfer(scene%network%element_nodes, [0_int8]))
        call add_bytes(transfer(scene%network%length0, [0_int8]))
        call add_bytes(transfer(scene%external_force, [0_int8]))
        call add_bytes(transfer(scene%path%time, [0_int8]))
        call add_bytes(transfer(scene%path%p_force, [0_int8]))
        call add_bytes(transfer(scene%path%p_disp, [0_int8]))
        write(hash, '(z8.8, z8.8)') state(1), state(2)
    contains
        subroutine add_bytes(bytes)
            integer(int8), intent(in) :: bytes(:)
            integer :: i
            do i = 1, size(bytes)
                state = mod(ieor(state, iand(int(bytes(i), int64), 255_int64)) &
                    * hash_prime, two_32)
            end do
        end subroutine add_bytes
    end function get_input_hash

end module yarnfort_output_restart
