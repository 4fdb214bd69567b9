! SPDX-License-Identifier: MIT
!> Continuation along the load path (paper section 2.6): steps in pseudo-time from knot
!> to knot, each solved from the previous converged state; a failed step is cut, an
!> easy one lets the next step grow. Every converged step goes to the observer before
!> the next one starts.
module yarnfort_solver_continuation
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error, prefix_error
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_assembly_assemble, only: assemble_internal_force
    use yarnfort_solver_newton, only: newton_solver_type, newton_stats_type
    use yarnfort_solver_timer, only: wall_time
    implicit none
    private

    public :: step_state_type, step_observer_type, run_continuation, get_step_state

    !> A converged state of the net.
    type :: step_state_type
        integer :: step = 0
        real(wp) :: time = 0.0_wp, p_force = 0.0_wp, p_disp = 0.0_wp
        !> Node positions (3, n_nodes), element tension, stretch and reference length.
        real(wp), allocatable :: position(:, :), tension(:), stretch(:), length0(:)
        !> Force applied by each support set on the net, (3, n_supports).
        real(wp), allocatable :: reaction(:, :)
        type(newton_stats_type) :: newton
        !> Step cuts before this step converged, and its wall time in seconds.
        integer :: step_cuts = 0
        real(wp) :: wall_time = 0.0_wp
    end type step_state_type

    !> Receives every converged step and every step cut (output, progress, tests).
    type, abstract :: step_observer_type
    contains
        procedure(on_step_interface), deferred :: on_step
        procedure(on_cut_interface), deferred :: on_cut
    end type step_observer_type

    abstract interface
        subroutine on_step_interface(self, scene, state, error)
            import :: step_observer_type, scene_type, step_state_type, error_type
            class(step_observer_type), intent(inout) :: self
            type(scene_type), intent(in) :: scene
            type(step_state_type), intent(in) :: state
            type(error_type), allocatable, intent(out) :: error
        end subroutine on_step_interface

        subroutine on_cut_interface(self, time, step, reason)
            import :: step_observer_type, wp
            class(step_observer_type), intent(inout) :: self
            real(wp), intent(in) :: time, step
            character(len=*), intent(in) :: reason
        end subroutine on_cut_interface
    end interface

    !> Pseudo-times closer than this (relative to the path length) are the same knot.
    real(wp), parameter :: knot_tolerance = 1.0e-12_wp

contains

    !> Follow the scene's load path from its first knot to its last.
    subroutine run_continuation(scene, newton, observer, error)
        type(scene_type), intent(in) :: scene
        type(newton_solver_type), intent(inout) :: newton
        class(step_observer_type), intent(inout) :: observer
        type(error_type), allocatable, intent(out) :: error
        real(wp), allocatable :: u(:), u_trial(:)
        real(wp) :: t, t_end, dt, t_next, p_force, p_disp, span, start
        integer :: step, cuts, knot
        type(newton_stats_type) :: stats
        type(step_state_type) :: state
        type(error_type), allocatable :: step_error
        character(len=200) :: buffer

        associate(path => scene%path)
            t = path%time(1)
            t_end = path%time(size(path%time))
            span = t_end - t
            allocate(u(scene%dofs%n_unknowns))
            call scene%dofs%restrict(scene%network%position, u)

            ! Step 0: equilibrium at the first knot.
            start = wall_time()
            call path%get_factors(t, p_force, p_disp)
            call newton%solve(u, p_force, p_disp, stats, error)
            if (allocated(error)) then
                call prefix_error(error, 'initial state (time 0)')
                return
            end if
            step = 0
            call get_step_state(scene, u, t, p_force, p_disp, state, error)
            if (allocated(error)) return
            state%step = step
            state%newton = stats
            state%wall_time = wall_time() - start
            call observer%on_step(scene, state, error)
            if (allocated(error)) return

            dt = min(scene%solver%initial_step, scene%solver%max_step)
            knot = 2
            cuts = 0
            start = wall_time()
            do while (t < t_end - knot_tolerance * span)
                do while (path%time(knot) <= t + knot_tolerance * span)
                    knot = knot + 1
                end do
                t_next = min(t + dt, path%time(knot))
                ! Do not leave a sliver before the knot.
                if (path%time(knot) - t_next < 0.25_wp * dt) t_next = path%time(knot)
                call path%get_factors(t_next, p_force, p_disp)
                u_trial = u
                call newton%solve(u_trial, p_force, p_disp, stats, step_error)
                if (allocated(step_error)) then
                    cuts = cuts + 1
                    call observer%on_cut(t, t_next - t, step_error%message)
                    dt = (t_next - t) * scene%solver%step_cut
                    if (dt < scene%solver%min_step .or. cuts > scene%solver%max_step_cuts) then
                        write(buffer, '("step from time ", g0.6, " failed after ", i0, &
                            & " cuts (step ", es9.2, ", min_step ", es9.2, "); last error")') &
                            t, cuts, dt, scene%solver%min_step
                        call fatal_error(error, trim(buffer) // ': ' // step_error%message)
                        return
                    end if
                    deallocate(step_error)
                    cycle
                end if
                step = step + 1
                u = u_trial
                call get_step_state(scene, u, t_next, p_force, p_disp, state, error)
                if (allocated(error)) return
                state%step = step
                state%newton = stats
                state%step_cuts = cuts
                state%wall_time = wall_time() - start
                call observer%on_step(scene, state, error)
                if (allocated(error)) return
                if (stats%iterations <= scene%solver%easy_iterations .and. cuts == 0) then
                    dt = min((t_next - t) * scene%solver%step_growth, scene%solver%max_step)
                else
                    dt = min(max(dt, t_next - t), scene%solver%max_step)
                end if
                t = t_next
                cuts = 0
                start = wall_time()
            end do
        end associate
    end subroutine run_continuation

    !> The state of the net for unknowns u at the given load factors.
    subroutine get_step_state(scene, u, t, p_force, p_disp, state, error)
        type(scene_type), intent(in) :: scene
        real(wp), intent(in) :: u(:), t, p_force, p_disp
        type(step_state_type), intent(inout) :: state
        type(error_type), allocatable, intent(out) :: error
        real(wp), allocatable :: internal(:)
        integer :: s, i, c, k, n_elements

        n_elements = scene%network%n_elements()
        state%time = t
        state%p_force = p_force
        state%p_disp = p_disp
        if (.not. allocated(state%position)) then
            allocate(state%position(3, scene%network%n_nodes()))
            allocate(state%tension(n_elements), state%stretch(n_elements))
        end if
        state%length0 = scene%network%length0
        call scene%dofs%expand(u, p_disp, state%position)
        allocate(internal(3 * scene%network%n_nodes()))
        call assemble_internal_force(scene, state%position, internal, state%tension, &
            state%stretch, error)
        if (allocated(error)) return
        internal = internal - p_force * scene%external_force
        if (allocated(state%reaction)) deallocate(state%reaction)
        allocate(state%reaction(3, size(scene%supports)), source=0.0_wp)
        do s = 1, size(scene%supports)
            do i = 1, size(scene%supports(s)%coordinates)
                c = scene%supports(s)%coordinates(i)
                k = mod(c - 1, 3) + 1
                state%reaction(k, s) = state%reaction(k, s) + internal(c)
            end do
        end do
    end subroutine get_step_state

end module yarnfort_solver_continuation
