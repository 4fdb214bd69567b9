! SPDX-License-Identifier: MIT
!> Continuation along the load path (paper section 2.6): steps in pseudo-time from knot
!> to knot, each solved from the previous converged state; a failed step is cut, an
!> easy one lets the next step grow. Step sizes (initial_step, min_step, max_step and
!> the step carried on) are fractions of the knot interval being followed, so a long
!> path takes as many steps per interval as a short one. Every converged step goes to the observer before
!> the next one starts, then a restart snapshot of it (on_checkpoint): a run started
!> from that snapshot takes the same steps as one that never stopped.
module yarnfort_solver_continuation
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error, prefix_error
    use yarnfort_text, only: format_short, format_integer, format_real
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_solver_newton, only: newton_stats_type
    use yarnfort_solver_stepper, only: load_stepper_type, step_state_type
    use yarnfort_solver_restart, only: restart_type
    use yarnfort_solver_timer, only: wall_time
    use yarnfort_solver_interrupt, only: interrupt_requested, interrupt_stat
    implicit none
    private

    public :: step_state_type, step_observer_type, run_continuation

    !> Receives every converged step and every step cut (output, progress, tests).
    type, abstract :: step_observer_type
    contains
        procedure(on_step_interface), deferred :: on_step
        !> Told of every step cut (the time, the step tried and why it failed).
        procedure :: on_cut
        !> Receives the restart snapshot of every converged step, after on_step.
        procedure :: on_checkpoint
    end type step_observer_type

    abstract interface
        subroutine on_step_interface(self, scene, state, error)
            import :: step_observer_type, scene_type, step_state_type, error_type
            class(step_observer_type), intent(inout) :: self
            type(scene_type), intent(in) :: scene
            type(step_state_type), intent(in) :: state
            type(error_type), allocatable, intent(out) :: error
        end subroutine on_step_interface
    end interface

    !> Pseudo-times closer than this (relative to the path length) are the same knot.
    real(wp), parameter :: knot_tolerance = 1.0e-12_wp

contains

    !> The default: snapshots are not kept.
    subroutine on_checkpoint(self, scene, snapshot, error)
        class(step_observer_type), intent(inout) :: self
        type(scene_type), intent(in) :: scene
        type(restart_type), intent(in) :: snapshot
        type(error_type), allocatable, intent(out) :: error
    end subroutine on_checkpoint

    !> The default: cuts are not reported.
    subroutine on_cut(self, time, step, reason)
        class(step_observer_type), intent(inout) :: self
        real(wp), intent(in) :: time, step
        character(len=*), intent(in) :: reason
    end subroutine on_cut

    !> Follow the scene's load path from its first knot to its last, or from the step
    !> of a `restart` snapshot on; stop early after `max_steps` converged load steps
    !> (> 0) and then set `stopped`.
    subroutine run_continuation(scene, stepper, observer, error, restart, max_steps, stopped)
        type(scene_type), intent(in) :: scene
        class(load_stepper_type), intent(inout) :: stepper
        class(step_observer_type), intent(inout) :: observer
        type(error_type), allocatable, intent(out) :: error
        type(restart_type), intent(in), optional :: restart
        integer, intent(in), optional :: max_steps
        logical, intent(out), optional :: stopped
        real(wp) :: t, t_end, dt, t_next, span, start, previous_load
        real(wp) :: interval
        real(wp), allocatable :: factors(:)
        integer :: step, cuts, knot, iterations, first_step
        type(newton_stats_type) :: stats
        type(step_state_type) :: state
        type(restart_type) :: snapshot
        type(error_type), allocatable :: step_error, jump_error
        character(len=200) :: buffer
        logical :: jumped

        if (present(stopped)) stopped = .false.
        allocate(factors(scene%path%n_channels()))
        associate(path => scene%path)
            t = path%time(1)
            t_end = path%time(size(path%time))
            span = t_end - t

            if (present(restart)) then
                ! Go on from the snapshot's converged step, as the run that wrote it would.
                if (restart%knot < 2 .or. restart%knot > size(path%time) .or. &
                        .not. (restart%time >= t .and. restart%time <= t_end)) then
                    call fatal_error(error, 'restart file: its time or knot is not on ' &
                        // 'the load path')
                    return
                end if
                call stepper%restore_state(restart, error)
                if (allocated(error)) return
                t = restart%time
                dt = restart%next_step
                knot = restart%knot
                step = restart%step
                previous_load = restart%previous_load
                if (size(restart%factors) /= size(factors)) then
                    call fatal_error(error, 'restart file: its load channels are not those ' &
                        // 'of the load path')
                    return
                end if
                factors = restart%factors
            else
                ! Step 0: equilibrium at the first knot.
                start = wall_time()
                call path%get_factors(t, factors)
                call stepper%try_step(factors, stats, iterations, error)
                if (allocated(error)) then
                    if (interrupt_requested()) then
                        call stop_interrupted(-1)
                        return
                    end if
                    call prefix_error(error, 'initial state (time 0)')
                    error%message = error%message // initial_state_hint(error%message)
                    return
                end if
                call stepper%accept()
                step = 0
                dt = min(scene%solver%initial_step, scene%solver%max_step)
                knot = 2
                call report(0)
                if (allocated(error)) return
                previous_load = sum(factors)
                call checkpoint(t)
                if (allocated(error)) return
            end if

            first_step = step
            cuts = 0
            start = wall_time()
            do while (t < t_end - knot_tolerance * span)
                if (interrupt_requested()) then
                    call stop_interrupted(step)
                    return
                end if
                if (present(max_steps)) then
                    if (max_steps > 0 .and. step - first_step >= max_steps) then
                        if (present(stopped)) stopped = .true.
                        return
                    end if
                end if
                do while (path%time(knot) <= t + knot_tolerance * span)
                    knot = knot + 1
                end do
                ! dt is a fraction of the interval of the knot ahead.
                interval = path%time(knot) - path%time(knot - 1)
                t_next = min(t + dt * interval, path%time(knot))
                ! Do not leave a sliver before the knot; but never after a cut, whose
                ! shorter step that stretch would undo (step_cut > 0.8: no cut at all).
                if (cuts == 0 .and. path%time(knot) - t_next < 0.25_wp * dt * interval) &
                    t_next = path%time(knot)
                call path%get_factors(t_next, factors)
                call stepper%try_step(factors, stats, iterations, step_error)
                if (allocated(step_error)) then
                    if (interrupt_requested()) then
                        call stop_interrupted(step)
                        return
                    end if
                    cuts = cuts + 1
                    call observer%on_cut(t, t_next - t, step_error%message)
                    dt = (t_next - t) / interval * scene%solver%step_cut
                    if (dt >= scene%solver%min_step .and. cuts <= scene%solver%max_step_cuts) then
                        deallocate(step_error)
                        cycle
                    end if
                    ! No step size works: a jump to the smallest step's load, where the
                    ! stepper has one for the way it failed (a slip instability).
                    call stepper%try_jump(factors, stats, iterations, jumped, jump_error)
                    if (.not. jumped .or. allocated(jump_error)) then
                        write(buffer, '("step from time ", g0.6, " failed after ", i0, &
                            & " cuts (step ", a, " of the knot interval, min_step ", a, &
                            & "); last error")') t, cuts, format_short(dt), &
                            format_short(scene%solver%min_step)
                        call fatal_error(error, trim(buffer) // ': ' // step_error%message)
                        if (jumped) error%message = error%message // '; then ' &
                            // jump_error%message
                        return
                    end if
                end if
                call stepper%accept()
                step = step + 1
                state%time = t_next
                if (stepper%growth_iterations(iterations) <= scene%solver%easy_iterations &
                        .and. cuts == 0) then
                    dt = min((t_next - t) / interval * scene%solver%step_growth, &
                        scene%solver%max_step)
                else
                    dt = min(max(dt, (t_next - t) / interval), scene%solver%max_step)
                end if
                ! A short step to a knot does not make the next one shorter than min_step.
                dt = max(dt, scene%solver%min_step)
                call report(cuts)
                if (allocated(error)) return
                call checkpoint(t_next)
                if (allocated(error)) return
                t = t_next
                cuts = 0
                start = wall_time()
            end do
        end associate
    contains
        !> The error of a run stopped by Ctrl-C while solving the step after `last` (-1:
        !> step 0): what the output keeps, the last converged step and its load.
        subroutine stop_interrupted(last)
            integer, intent(in) :: last
            real(wp), allocatable :: kept(:)
            character(len=:), allocatable :: loads
            integer :: c

            if (last < 0) then
                call fatal_error(error, 'interrupted (SIGINT, Ctrl-C) while solving the ' &
                    // 'initial state (step 0); no step converged, so nothing is kept to ' &
                    // 'restart from', stat=interrupt_stat)
                return
            end if
            allocate(kept(size(factors)))
            call scene%path%get_factors(t, kept)
            loads = ''
            do c = 1, size(kept)
                loads = loads // merge(', ', '  ', c > 1) // trim(scene%path%channel(c)) &
                    // ' = ' // format_real(kept(c))
            end do
            call fatal_error(error, 'interrupted (SIGINT, Ctrl-C) while solving step ' &
                // format_integer(last + 1) // '; kept: steps up to the last converged ' &
                // 'step ' // format_integer(last) // ' (time ' // format_real(t) // ';' &
                // loads(2:) // ')', stat=interrupt_stat)
        end subroutine stop_interrupted

        !> What in a scene usually makes its initial state fail, for the failure `message`
        !> (the cases of tests/cli/test_interrupt.py): a user reads the scene, not KINSOL.
        function initial_state_hint(message) result(hint)
            character(len=*), intent(in) :: message
            character(len=:), allocatable :: hint
            integer :: c

            if (index(message, 'singular') > 0) then
                hint = '. Hint: a singular matrix usually means that a node or a part of ' &
                    // 'the network is held in no way in some direction (a rigid-body ' &
                    // 'motion: a &support is missing, e.g. fix = ''z'' for a planar scene), ' &
                    // 'or that a loaded node sits on straight strings at zero tension, ' &
                    // 'which have no stiffness across them (&solver slack_stiffness = 0)'
            else
                hint = '. Hint: the initial state is solved in one step from the drawn ' &
                    // 'geometry; that usually fails when the load at the first knot of ' &
                    // '&path is large (start the path at 0 and let the steps ramp it), ' &
                    // 'when prestress or reference lengths (length0, stretch) are far from ' &
                    // 'the drawn lengths, or in a clamped knit with sides = ''free'' whose ' &
                    // 'cast-on and bind-off threads are not taut (&fabric edge_material: a ' &
                    // 'yarn type with a prestress well above the loops'')'
            end if
            do c = 1, size(factors)
                if (factors(c) /= 0.0_wp) hint = hint // '; this path starts at ' &
                    // trim(scene%path%channel(c)) // ' = ' // format_real(factors(c))
            end do
        end function initial_state_hint

        subroutine report(step_cuts)
            integer, intent(in) :: step_cuts
            call stepper%get_state(state, error)
            if (allocated(error)) return
            state%step = step
            if (step == 0) state%time = t
            state%newton = stats
            state%newton_iterations = iterations
            state%step_cuts = step_cuts
            state%wall_time = wall_time() - start
            if (step == 0) then
                state%direction = 0
            else
                state%direction = nint(sign(1.0_wp, sum(factors) - previous_load))
                if (sum(factors) == previous_load) state%direction = 0
            end if
            previous_load = sum(factors)
            call observer%on_step(scene, state, error)
        end subroutine report

        !> Hand the accepted state at `time` to the observer as a restart snapshot.
        subroutine checkpoint(time)
            real(wp), intent(in) :: time
            call stepper%save_state(snapshot)
            snapshot%step = step
            snapshot%time = time
            ! t is still the time of the step before (checkpoint comes before t moves on).
            snapshot%time_old = t
            snapshot%next_step = dt
            snapshot%knot = knot
            snapshot%previous_load = previous_load
            snapshot%n_nodes = scene%network%n_nodes()
            snapshot%n_elements = scene%network%n_elements()
            snapshot%n_unknowns = scene%dofs%n_unknowns
            snapshot%n_passages = scene%passages%size()
            call observer%on_checkpoint(scene, snapshot, error)
        end subroutine checkpoint
    end subroutine run_continuation

end module yarnfort_solver_continuation
