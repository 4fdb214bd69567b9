! SPDX-License-Identifier: MIT
!> The step observer that writes a run's files: curve.csv after every converged step, a
!> VTK state every `vtk_every` steps (and always the last one, written by `finish`), and
!> the restart file of every converged step, flushed to disk with the tables at most
!> every `sync_interval` seconds and by `finish`. It holds the output folder's lock from
!> `open` (or `lock`) to `finish`, and lists every file it writes in the folder's
!> manifest (yarnfort_output_manifest), as it first creates it: a new run deletes only
!> files listed there. A symbolic link at any name it writes is refused when the folder
!> is locked, before anything is deleted or written.
!> Every write is checked; a failed one ends the run with an error (`failed` is then
!> set), and what was written before it stays.
module yarnfort_output_writer
    use, intrinsic :: iso_fortran_env, only: int64
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_text, only: string_type
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_solver_continuation, only: step_observer_type, step_state_type
    use yarnfort_output_curve, only: curve_writer_type, curve_file_name
    use yarnfort_output_reactions, only: reactions_writer_type, reactions_file_name
    use yarnfort_output_contacts, only: contacts_writer_type, contacts_file_name
    use yarnfort_output_table, only: table_writer_type
    use yarnfort_output_vtk, only: vtk_writer_type, get_state_name, get_part_name, &
        get_multiblock_name, collection_file_name
    use yarnfort_output_filesystem, only: make_folder, folder_lock_type, rename_file, &
        remove_file, open_new_file, close_new_file, get_links, refuse_link, sync_file
    use yarnfort_output_manifest, only: manifest_type, manifest_file_name, is_own_name, &
        is_bookkeeping_name, part_prefixes
    use yarnfort_solver_restart, only: restart_type
    use yarnfort_output_restart_file, only: write_restart, remove_restart, restart_file_name, &
        sync_restart, synced_file_name
    implicit none
    private

    public :: output_writer_type, input_file_name

    !> The effective input, echoed for provenance.
    character(len=*), parameter :: input_file_name = 'input.nml'
    !> Least seconds between two flushes of the tables and restart.dat to disk (fsync): a
    !> power cut loses about this much of a run, and a flush costs a few ms (docs/
    !> decisions.md, "restart.dat is flushed to disk by time, not by step").
    real(wp), parameter :: sync_interval = 10.0_wp

    type, extends(step_observer_type) :: output_writer_type
        character(len=:), allocatable :: folder
        integer :: vtk_every = 1
        type(curve_writer_type) :: curve
        !> reactions.csv (`&output node_reactions`).
        type(reactions_writer_type) :: reactions
        logical :: node_reactions = .false.
        !> contacts.csv (`&output contact_state` and sliding passages), from the snapshot
        !> of each step (on_checkpoint).
        type(contacts_writer_type) :: contacts
        logical :: contact_state = .false.
        type(vtk_writer_type) :: vtk
        type(manifest_type) :: manifest
        type(folder_lock_type) :: folder_lock
        !> The last converged state and the passage modes of its snapshot; whether its
        !> VTK state is due (written with the snapshot, on_checkpoint) or was skipped
        !> (written by finish).
        type(step_state_type) :: last
        integer, allocatable :: last_mode(:)
        real(wp), allocatable :: last_flow(:)
        logical :: state_due = .false.
        logical :: last_written = .true.
        !> Fingerprint of the input, stamped on the restart files (get_input_hash).
        character(len=16) :: input_hash = ''
        !> A write to the folder failed (the error of on_step or on_checkpoint).
        logical :: failed = .false.
        !> The clock count of the last flush to disk (or of open), and whether a restart
        !> file was written since.
        integer(int64) :: synced_at = 0
        logical :: unsynced = .false.
    contains
        !> Create the folder if needed and take its lock (also done by open).
        procedure :: lock => lock_writer
        procedure :: open => open_writer
        !> Write the effective input's echo (rendered by the caller) to folder/input.nml.
        procedure :: write_input
        procedure :: on_step
        procedure :: on_checkpoint
        !> Told the step and time a restart resumes after, before the files are opened.
        procedure :: on_resume
        procedure :: finish
    end type output_writer_type

contains

    !> Take the lock of the scene's output folder (created when missing, unless
    !> `create` is false: then a missing folder is left alone and not locked), and
    !> refuse a folder with a symbolic link at a name the program writes.
    subroutine lock_writer(self, folder, error, create)
        class(output_writer_type), intent(inout) :: self
        character(len=*), intent(in) :: folder
        type(error_type), allocatable, intent(out) :: error
        logical, intent(in), optional :: create
        logical :: exists

        self%folder = trim(folder)
        if (self%folder_lock%held()) return
        if (present(create)) then
            if (.not. create) then
                inquire(file=self%folder // '/.', exist=exists)
                if (.not. exists) return
            end if
        end if
        call make_folder(self%folder, error)
        if (allocated(error)) return
        call self%folder_lock%acquire(self%folder, error)
        if (allocated(error)) return
        call check_links(self%folder, error)
        if (allocated(error)) call self%folder_lock%release()
    end subroutine lock_writer

    !> Refuse a symbolic link in `folder` at a name the program writes (its files, their
    !> temporaries, the states, the manifest, the lock, the probe): a write there would
    !> follow it out of the folder. (Writes refuse links too; this says so before the run.)
    subroutine check_links(folder, error)
        character(len=*), intent(in) :: folder
        type(error_type), allocatable, intent(out) :: error
        character(len=:), allocatable :: names(:)
        integer :: i

        call get_links(folder, names, error)
        if (allocated(error)) return
        do i = 1, size(names)
            if (is_own_name(trim(names(i))) .or. is_bookkeeping_name(trim(names(i)))) then
                call refuse_link(folder // '/' // trim(names(i)), .true., error)
                return
            end if
        end do
    end subroutine check_links

    !> List a file written through `name`.tmp renamed to `name`: both names.
    subroutine list_atomic_file(self, name, error)
        class(output_writer_type), intent(inout) :: self
        character(len=*), intent(in) :: name
        type(error_type), allocatable, intent(out) :: error

        call self%manifest%add_file(name // '.tmp', error)
        if (.not. allocated(error)) call self%manifest%add_file(name, error)
    end subroutine list_atomic_file

    !> Lock the output folder, delete the files an earlier run listed in its manifest,
    !> and start the curve file; with `resume_step` (a restart), continue the folder's
    !> curve file and VTK states after that step instead (`resume_time`: the restart's
    !> time, which the curve row of that step must have; `resume_previous_time`: that of
    !> the step before, for the row before).
    subroutine open_writer(self, scene, error, resume_step, resume_time, resume_previous_time)
        class(output_writer_type), intent(inout) :: self
        type(scene_type), intent(in) :: scene
        type(error_type), allocatable, intent(out) :: error
        integer, intent(in), optional :: resume_step
        real(wp), intent(in), optional :: resume_time, resume_previous_time
        logical :: found

        self%vtk_every = scene%output%vtk_every
        self%node_reactions = scene%output%node_reactions
        self%contact_state = scene%output%contact_state .and. scene%passages%size() > 0
        self%vtk%ascii = trim(scene%output%vtk_format) == 'ascii'
        call system_clock(self%synced_at)
        call self%lock(scene%output%folder, error)
        if (.not. allocated(error)) then
            self%vtk%folder = self%folder
            call self%manifest%load(self%folder, found)
            if (present(resume_step)) then
                call resume_files(self, scene, resume_step, error, resume_time, &
                    resume_previous_time)
            else
                call start_files(self, scene, found, error)
                if (.not. allocated(error)) call start_contacts(self, error)
            end if
        end if
        if (allocated(error)) call self%folder_lock%release()
    end subroutine open_writer

    !> A new run: delete what the manifest lists (the files an earlier run wrote; regular
    !> files only), or without a manifest a restart file of ours, then start the manifest
    !> anew, empty, and the curve file.
    subroutine start_files(self, scene, listed, error)
        class(output_writer_type), intent(inout) :: self
        type(scene_type), intent(in) :: scene
        !> The folder has a manifest.
        logical, intent(in) :: listed
        type(error_type), allocatable, intent(out) :: error
        integer :: i

        do i = 1, size(self%manifest%states)
            call remove_state(self, self%manifest%states(i), error)
            if (allocated(error)) return
        end do
        do i = 1, size(self%manifest%files)
            call remove_file(self%folder // '/' // trim(self%manifest%files(i)), error)
            if (allocated(error)) return
        end do
        ! A restart file of an earlier version (no manifest) must not survive either:
        ! removed when its header says it is one of ours.
        if (.not. listed) call remove_restart(self%folder)
        self%manifest%states = self%manifest%states(:0)
        self%manifest%steps = self%manifest%steps(:0)
        self%manifest%times = self%manifest%times(:0)
        self%manifest%files = self%manifest%files(:0)
        call self%manifest%save(error)
        if (allocated(error)) return
        call self%vtk%set_files([character(len=1) :: ], [real(wp) :: ])
        call self%manifest%add_file(curve_file_name, error)
        if (.not. allocated(error)) call self%curve%open(self%folder, scene, error)
        if (allocated(error) .or. .not. self%node_reactions) return
        call self%manifest%add_file(reactions_file_name, error)
        if (.not. allocated(error)) call self%reactions%open(self%folder, error)
    end subroutine start_files

    !> Start contacts.csv when it is asked for.
    subroutine start_contacts(self, error)
        class(output_writer_type), intent(inout) :: self
        type(error_type), allocatable, intent(out) :: error

        if (.not. self%contact_state) return
        call self%manifest%add_file(contacts_file_name, error)
        if (.not. allocated(error)) call self%contacts%open(self%folder, error)
    end subroutine start_contacts

    !> A restart after `step`: keep curve rows and the listed states up to that step,
    !> delete the listed states after it (and any that is incomplete), and rewrite the
    !> manifest and states.pvd with what is kept. A listed reactions.csv or contacts.csv
    !> this run does not write is deleted (its rows would contradict this run's); one
    !> that is not listed is not ours and stays.
    subroutine resume_files(self, scene, step, error, time, previous_time)
        class(output_writer_type), intent(inout) :: self
        type(scene_type), intent(in) :: scene
        integer, intent(in) :: step
        type(error_type), allocatable, intent(out) :: error
        real(wp), intent(in), optional :: time, previous_time
        logical, allocatable :: keep(:)
        integer :: i

        call list_atomic_file(self, curve_file_name, error)
        if (allocated(error)) return
        call self%curve%resume(self%folder, scene, step, error, time, previous_time)
        if (allocated(error)) return
        if (self%node_reactions) then
            call list_atomic_file(self, reactions_file_name, error)
            if (.not. allocated(error)) call self%reactions%resume(self%folder, scene, step, &
                error)
        else
            call drop_file(self, reactions_file_name, error)
        end if
        if (allocated(error)) return
        if (self%contact_state) then
            call list_atomic_file(self, contacts_file_name, error)
            if (.not. allocated(error)) call self%contacts%resume(self%folder, step, error)
        else
            call drop_file(self, contacts_file_name, error)
        end if
        if (allocated(error)) return
        allocate(keep(size(self%manifest%states)))
        do i = 1, size(keep)
            keep(i) = self%manifest%steps(i) <= step
            if (keep(i)) keep(i) = is_complete(self%folder // '/' &
                // trim(self%manifest%states(i)))
            if (keep(i)) keep(i) = .not. any(self%manifest%states(i + 1:) &
                == self%manifest%states(i))
            if (.not. keep(i)) then
                call remove_state(self, self%manifest%states(i), error)
                if (allocated(error)) return
            end if
        end do
        self%manifest%states = pack(self%manifest%states, keep)
        self%manifest%steps = pack(self%manifest%steps, keep)
        self%manifest%times = pack(self%manifest%times, keep)
        call self%manifest%save(error)
        if (allocated(error)) return
        call self%vtk%set_files(self%manifest%states, self%manifest%times)
        call list_atomic_file(self, collection_file_name, error)
        if (.not. allocated(error)) call self%vtk%write_collection(error)
    end subroutine resume_files

    !> Delete the state file `name`, its multiblock file and its other blocks (those of
    !> any scene).
    subroutine remove_state(self, name, error)
        class(output_writer_type), intent(inout) :: self
        character(len=*), intent(in) :: name
        type(error_type), allocatable, intent(out) :: error
        integer :: part

        call remove_file(self%folder // '/' // trim(name), error)
        if (.not. allocated(error)) call remove_file(self%folder // '/' &
            // get_multiblock_name(trim(name)), error)
        do part = 1, size(part_prefixes)
            if (.not. allocated(error)) call remove_file(self%folder // '/' &
                // get_part_name(trim(name), part), error)
        end do
    end subroutine remove_state

    !> A restart that does not write the table `name`: delete it if a run of ours wrote
    !> it (listed), and list it no more; leave it alone otherwise.
    subroutine drop_file(self, name, error)
        class(output_writer_type), intent(inout) :: self
        character(len=*), intent(in) :: name
        type(error_type), allocatable, intent(out) :: error
        logical, allocatable :: keep(:)

        if (.not. self%manifest%has_file(name)) return
        call remove_file(self%folder // '/' // name, error)
        if (allocated(error)) return
        keep = self%manifest%files /= name .and. self%manifest%files /= name // '.tmp'
        call remove_file(self%folder // '/' // name // '.tmp', error)
        if (allocated(error)) return
        self%manifest%files = pack(self%manifest%files, keep)
    end subroutine drop_file

    !> Whether a state file is whole: it ends with the closing tag.
    logical function is_complete(path)
        character(len=*), intent(in) :: path
        character(len=*), parameter :: closing = '</VTKFile>' // achar(10)
        character(len=len(closing)) :: tail
        integer :: unit, status
        integer(8) :: file_size

        is_complete = .false.
        open(newunit=unit, file=path, access='stream', form='unformatted', status='old', &
            action='read', iostat=status)
        if (status /= 0) return
        inquire(unit=unit, size=file_size)
        if (file_size >= len(closing)) then
            read(unit, pos=file_size - len(closing) + 1, iostat=status) tail
            is_complete = status == 0 .and. tail == closing
        end if
        close(unit)
    end function is_complete

    !> Write the lines of `echo` to folder/input.nml (through input.nml.tmp, renamed when
    !> complete). The caller renders the echo, so that output/ does not read the input.
    subroutine write_input(self, echo, error)
        class(output_writer_type), intent(inout) :: self
        type(string_type), intent(in) :: echo(:)
        type(error_type), allocatable, intent(out) :: error
        type(error_type), allocatable :: ignored
        character(len=:), allocatable :: path, temporary
        integer :: unit, i, status

        path = self%folder // '/' // input_file_name
        temporary = path // '.tmp'
        call list_atomic_file(self, input_file_name, error)
        if (allocated(error)) return
        call open_new_file(unit, temporary, error)
        if (allocated(error)) then
            call remove_file(temporary, ignored)
            return
        end if
        ! A failed write shows when closing: the file is shorter than what was written.
        do i = 1, size(echo)
            write(unit, '(a)', iostat=status) echo(i)%text
        end do
        call close_new_file(unit, temporary, error)
        if (allocated(error)) return
        call rename_file(temporary, path, error)
    end subroutine write_input

    subroutine on_step(self, scene, state, error)
        class(output_writer_type), intent(inout) :: self
        type(scene_type), intent(in) :: scene
        type(step_state_type), intent(in) :: state
        type(error_type), allocatable, intent(out) :: error

        call self%curve%write_step(scene, state, error)
        if (.not. allocated(error) .and. self%node_reactions) &
            call self%reactions%write_step(scene, state, error)
        call note_written(self, error)
        if (allocated(error)) return
        if (self%contact_state .and. self%vtk_every <= 0) self%last = state
        if (self%vtk_every > 0) then
            self%last = state
            self%state_due = mod(state%step, self%vtk_every) == 0
            self%last_written = .false.
        end if
    end subroutine on_step

    !> The default: nothing to say.
    subroutine on_resume(self, step, time)
        class(output_writer_type), intent(inout) :: self
        integer, intent(in) :: step
        real(wp), intent(in) :: time
    end subroutine on_resume

    !> Write the VTK state of the step just written when due (it needs the snapshot's
    !> passage modes), then the restart file.
    subroutine on_checkpoint(self, scene, snapshot, error)
        class(output_writer_type), intent(inout) :: self
        type(scene_type), intent(in) :: scene
        type(restart_type), intent(in) :: snapshot
        type(error_type), allocatable, intent(out) :: error
        logical :: due

        if (allocated(snapshot%mode)) then
            self%last_mode = snapshot%mode
        else
            self%last_mode = [integer :: ]
        end if
        if (allocated(snapshot%flow)) then
            self%last_flow = snapshot%flow
        else
            self%last_flow = [real(wp) :: ]
        end if
        if (self%contact_state) then
            if (.not. allocated(snapshot%flow) .or. .not. allocated(snapshot%mode)) then
                call fatal_error(error, "cannot write '" // self%contacts%path // "': the " &
                    // 'step has no friction state')
            else
                call self%contacts%write_step(scene, self%last, snapshot%mode, snapshot%flow, &
                    error)
            end if
            if (allocated(error)) then
                self%failed = .true.
                return
            end if
        end if
        if (self%state_due) then
            call write_last_state(self, scene, error)
            if (allocated(error)) return
        end if
        ! Flushed when due: the tables first, so that the rows of the restart's step
        ! are on disk when it is.
        due = seconds_since(self%synced_at) >= sync_interval
        call list_atomic_file(self, restart_file_name, error)
        if (.not. allocated(error)) call list_atomic_file(self, synced_file_name, error)
        if (due .and. .not. allocated(error)) call sync_tables(self, error)
        if (.not. allocated(error)) &
            call write_restart(self%folder, snapshot, self%input_hash, error, sync=due)
        if (allocated(error)) then
            self%failed = .true.
            return
        end if
        self%unsynced = .not. due
        if (due) call system_clock(self%synced_at)
    end subroutine on_checkpoint

    !> Seconds since the clock count `start`.
    real(wp) function seconds_since(start)
        integer(int64), intent(in) :: start
        integer(int64) :: now, rate

        call system_clock(now, rate)
        seconds_since = real(now - start, wp) / real(max(rate, 1_int64), wp)
    end function seconds_since

    !> Flush the per-step tables (their rows are already written and flushed to the
    !> system) and the manifest to disk.
    subroutine sync_tables(self, error)
        class(output_writer_type), intent(inout) :: self
        type(error_type), allocatable, intent(out) :: error

        call sync_table(self%curve)
        if (.not. allocated(error)) call sync_table(self%reactions)
        if (.not. allocated(error)) call sync_table(self%contacts)
        if (.not. allocated(error)) call sync_file(self%folder // '/' // manifest_file_name, &
            error)
    contains
        subroutine sync_table(table)
            class(table_writer_type), intent(in) :: table
            if (allocated(table%path)) call sync_file(table%path, error)
        end subroutine sync_table
    end subroutine sync_tables

    !> The VTK state of the last step: listed in the manifest, then written.
    subroutine write_last_state(self, scene, error)
        class(output_writer_type), intent(inout) :: self
        type(scene_type), intent(in) :: scene
        type(error_type), allocatable, intent(out) :: error

        ! The first state is followed by states.pvd at once (vtk%write_state).
        call list_atomic_file(self, collection_file_name, error)
        if (.not. allocated(error)) call self%manifest%add_state(get_state_name( &
            self%last%step), self%last%step, self%last%time, error)
        if (.not. allocated(error)) then
            if (.not. allocated(self%last_mode)) self%last_mode = [integer :: ]
            if (.not. allocated(self%last_flow)) self%last_flow = [real(wp) :: ]
            call self%vtk%write_state(scene, self%last, self%last_mode, self%last_flow, error)
        end if
        call note_written(self, error)
    end subroutine write_last_state

    !> After a write of the last state's files: failed if `error`, else nothing is due.
    subroutine note_written(self, error)
        class(output_writer_type), intent(inout) :: self
        type(error_type), allocatable, intent(in) :: error

        self%failed = self%failed .or. allocated(error)
        if (allocated(error)) return
        self%state_due = .false.
        self%last_written = .true.
    end subroutine note_written

    !> Write the last converged state if it was skipped and states.pvd complete, close
    !> the files, flush the tables and restart.dat to disk if they were not since the
    !> last restart file, and release the folder's lock.
    subroutine finish(self, scene, error)
        class(output_writer_type), intent(inout) :: self
        type(scene_type), intent(in) :: scene
        type(error_type), allocatable, intent(out) :: error
        type(error_type), allocatable :: sync_error

        if (.not. self%last_written .and. self%vtk_every > 0 .and. allocated(self%last%position)) &
            call write_last_state(self, scene, error)
        if (.not. allocated(error) .and. self%vtk_every > 0 .and. allocated(self%vtk%files)) then
            if (self%vtk%listed /= self%vtk%n_files) call self%vtk%write_collection(error)
            if (allocated(error)) self%failed = .true.
        end if
        call close_table(self%curve)
        call close_table(self%contacts)
        call close_table(self%reactions)
        call self%manifest%close()
        if (self%unsynced) then
            call sync_tables(self, sync_error)
            if (.not. allocated(sync_error)) call sync_restart(self%folder, sync_error)
            if (allocated(sync_error) .and. .not. allocated(error)) then
                self%failed = .true.
                call move_alloc(sync_error, error)
            end if
            self%unsynced = .false.
        end if
        call self%folder_lock%release()
    contains
        !> Close a CSV file; its error is the run's unless an earlier one is.
        subroutine close_table(table)
            class(table_writer_type), intent(inout) :: table
            type(error_type), allocatable :: close_error

            call table%close(close_error)
            if (allocated(close_error) .and. .not. allocated(error)) then
                self%failed = .true.
                call move_alloc(close_error, error)
            end if
        end subroutine close_table
    end subroutine finish

end module yarnfort_output_writer
