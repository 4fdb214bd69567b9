! SPDX-License-Identifier: MIT
!> Proxy module for load steps with sliding at contact nodes: it keeps the public
!> friction_stepper_type and its set-up; the concerns live in contact/stepper/:
!> - monolithic.f90: positions and flows solved together for a stick/slip active set,
!>   updated like a return mapping until it settles (the default scheme);
!> - staggered.f90: the paper's two-step method (Fig. 4), elastic and sliding solves
!>   in turn, finished by monolithic solves;
!> - active_set.f90: the stick/slip rules after each solve, locks at the minimum
!>   length, chatter damping;
!> - predictor.f90 and slip_front.f90: a step's predicted state and start set, and
!>   the capstan march of new slips along their yarns;
!> - jump.f90: a step whose rounds settle at no step size down to min_step (a slip
!>   instability) is reached by viscous slip steps (try_jump);
!> - base.f90: the stepper's state; trace.f90: where a step's work goes (for
!>   benchmarks/steps_trace).
!> Every solve starts with chord steps (solve_options_type%chord_steps), in both
!> schemes.
module yarnfort_contact_friction_stepper
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_linalg_linear_solver, only: linear_solver_type
    use yarnfort_linalg_factory, only: new_linear_solver, get_friction_solver_names, &
        chosen_lu_name
    use yarnfort_linalg_composite_condensed, only: condensed_solver_type
    use yarnfort_linalg_composite_bordered, only: bordered_solver_type
    use yarnfort_solver_newton, only: new_newton_solver, newton_stats_type
    use yarnfort_solver_elastic_problem, only: new_elastic_problem
    use yarnfort_solver_stepper, only: step_state_type, start_stepper, accept_trial, &
        save_common, restore_common
    use yarnfort_solver_state, only: fill_step_state
    use yarnfort_solver_restart, only: restart_type, stepper_friction
    use yarnfort_contact_friction_problem, only: new_friction_problem, mode_stick
    use yarnfort_contact_stepper_trace, only: step_trace_type
    use yarnfort_contact_stepper_base, only: friction_stepper_base_type, start_trial
    use yarnfort_contact_stepper_monolithic, only: try_monolithic
    use yarnfort_contact_stepper_staggered, only: try_staggered
    use yarnfort_contact_stepper_jump, only: try_slip_jump
    implicit none
    private

    public :: friction_stepper_type, new_friction_stepper, step_trace_type

    !> Load steps with sliding at contact nodes (module notes).
    type, extends(friction_stepper_base_type) :: friction_stepper_type
    contains
        procedure :: try_step
        procedure :: try_jump
        procedure :: accept
        procedure :: get_state
        procedure :: save_state
        procedure :: restore_state
        final :: finalize
    end type friction_stepper_type

contains

    !> Set up the chosen scheme; `linear_name` is the linear solver for the elastic
    !> solves. The sliding systems are unsymmetric: when `linear_name` is a Cholesky
    !> solver, the flows-only one uses the measured default for unsymmetric systems and
    !> the monolithic one KLU or UMFPACK, chosen per reduced pattern (chosen_lu_name),
    !> else both use `linear_name`. The monolithic one first eliminates its stick flows
    !> (yarnfort_linalg_composite_condensed).
    subroutine new_friction_stepper(self, scene, linear_name, error)
        type(friction_stepper_type), intent(out) :: self
        type(scene_type), target, intent(in) :: scene
        character(len=*), intent(in) :: linear_name
        type(error_type), allocatable, intent(out) :: error
        class(linear_solver_type), allocatable :: linear
        character(len=:), allocatable :: general_name, full_name
        integer :: n_p

        call start_stepper(self, scene)
        self%staggered = trim(scene%solver%scheme) == 'staggered'
        n_p = scene%passages%size()
        ! The flows-only system of the staggered sliding step has order n_p, the
        ! monolithic one (also the staggered step's finish) n_unknowns + n_p.
        call get_friction_solver_names(linear_name, int(n_p, 8), general_name, full_name)
        if (self%staggered) then
            allocate(self%elastic, self%sliding)
            call new_elastic_problem(self%elastic, scene)
            if (scene%dofs%n_unknowns > 0) then
                call new_linear_solver(linear, linear_name, error)
                if (allocated(error)) return
                call new_newton_solver(self%newton_elastic, self%elastic, linear, scene%solver, &
                    error)
                if (allocated(error)) return
            end if
            call new_friction_problem(self%sliding, scene, positions_frozen=.true.)
            call new_linear_solver(linear, general_name, error, unsymmetric=.true.)
            if (allocated(error)) return
            call new_newton_solver(self%newton_sliding, self%sliding, linear, scene%solver, error)
            if (allocated(error)) return
        end if
        ! The monolithic problem: the whole solve, or the staggered scheme's finish of a
        ! step (finish_monolithic), which takes full Newton steps only.
        allocate(self%full)
        call new_friction_problem(self%full, scene, positions_frozen=.false.)
        block
            type(condensed_solver_type), allocatable :: condensed
            type(bordered_solver_type), allocatable :: bordered
            ! Stick flows eliminated before factorising (linalg/composite/condensed); with
            ! the Cholesky default, the elastic block of the rest by `linear_name` and a
            ! few slipping flows as its border (linalg/composite/bordered).
            allocate(condensed)
            if (full_name == chosen_lu_name) then
                allocate(bordered)
                bordered%n_leading = scene%dofs%n_unknowns
                call new_linear_solver(bordered%leading, linear_name, error)
                if (allocated(error)) return
                call new_linear_solver(bordered%general, full_name, error)
                if (allocated(error)) return
                call move_alloc(bordered, condensed%inner)
            else
                call new_linear_solver(condensed%inner, full_name, error)
                if (allocated(error)) return
            end if
            condensed%first_candidate = scene%dofs%n_unknowns + 1
            call move_alloc(condensed, linear)
        end block
        call new_newton_solver(self%newton_full, self%full, linear, scene%solver, error)
        if (allocated(error)) return
        allocate(self%flow(n_p), source=0.0_wp)
        allocate(self%mode(n_p), source=mode_stick)
        self%flow_trial = self%flow
        self%mode_trial = self%mode
        ! Written to restart files whether valid or not.
        self%u_older = self%u
        self%flow_older = self%flow
    end subroutine new_friction_stepper

    subroutine try_step(self, factors, stats, iterations, error)
        class(friction_stepper_type), intent(inout) :: self
        real(wp), intent(in) :: factors(:)
        type(newton_stats_type), intent(out) :: stats
        integer, intent(out) :: iterations
        type(error_type), allocatable, intent(out) :: error

        call start_trial(self, factors)
        if (self%staggered) then
            call try_staggered(self, stats, iterations, error)
        else
            call try_monolithic(self, stats, iterations, error)
        end if
    end subroutine try_step

    !> Jump to the load `factors` after a slip instability (yarnfort_contact_stepper_jump).
    subroutine try_jump(self, factors, stats, iterations, attempted, error)
        class(friction_stepper_type), intent(inout) :: self
        real(wp), intent(in) :: factors(:)
        type(newton_stats_type), intent(out) :: stats
        integer, intent(out) :: iterations
        logical, intent(out) :: attempted
        type(error_type), allocatable, intent(out) :: error
        call try_slip_jump(self, factors, stats, iterations, attempted, error)
    end subroutine try_jump

    subroutine accept(self)
        class(friction_stepper_type), intent(inout) :: self
        self%last_trace = self%trace
        self%last_trace%mode_changes = count(self%mode_trial /= self%mode)
        self%trace = step_trace_type()
        ! The quadratic predictor only along a stretch of one active set: across a change
        ! of the set the path has a kink, and extrapolating it costs iterations
        ! (docs/decisions.md, "Predictor: secant, parabola along one active set, reversed
        ! at a turn").
        self%have_older = self%have_old .and. self%set_repeated &
            .and. all(self%mode_trial == self%mode)
        self%set_repeated = self%have_old .and. all(self%mode_trial == self%mode)
        if (self%have_older) then
            self%u_older = self%u_old
            self%flow_older = self%flow_old
            self%load_older = self%load_old
        end if
        self%from_initial = .not. (self%have_old .or. self%jumped)
        self%have_limits = self%limits_trial
        if (self%have_limits) self%at_limit = self%at_limit_trial
        self%u_old = self%u
        self%flow_old = self%flow
        self%load_old = sum(self%factors)
        self%have_old = .true.
        call accept_trial(self)
        self%flow = self%flow_trial
        self%mode = self%mode_trial
        ! Across a jump the path has no tangent: the next step is predicted from the new
        ! state alone.
        self%jumped = self%jump_steps_trial > 0
        if (self%jumped) then
            self%have_old = .false.
            self%have_older = .false.
            self%set_repeated = .false.
        end if
    end subroutine accept

    subroutine get_state(self, state, error)
        class(friction_stepper_type), intent(inout) :: self
        type(step_state_type), intent(inout) :: state
        type(error_type), allocatable, intent(out) :: error
        real(wp), allocatable :: length0(:)

        allocate(length0(self%scene%network%n_elements()))
        call self%scene%passages%get_length0(self%scene%network%length0, self%flow, length0)
        call fill_step_state(self%scene, self%u, length0, self%factors, state, error)
        state%n_passages = size(self%mode)
        state%n_slipping = count(self%mode /= mode_stick)
        state%n_held = self%n_damped
        state%jump_steps = 0
        if (self%jumped) state%jump_steps = self%jump_steps_trial
    end subroutine get_state

    !> Everything a step depends on besides the scene: the accepted state (whose flows
    !> give the reference lengths and the locks at the minimum length) and the two before
    !> it for the predictor.
    subroutine save_state(self, snapshot)
        class(friction_stepper_type), intent(in) :: self
        type(restart_type), intent(inout) :: snapshot

        call save_common(self, snapshot, stepper_friction, self%flow)
        snapshot%flow = self%flow
        snapshot%mode = self%mode
        snapshot%have_old = self%have_old
        snapshot%load_old = self%load_old
        if (self%have_old) then
            snapshot%u_old = self%u_old
            snapshot%flow_old = self%flow_old
        else
            snapshot%u_old = self%u
            snapshot%flow_old = self%flow
        end if
        snapshot%have_older = self%have_older
        snapshot%set_repeated = self%set_repeated
        snapshot%load_older = self%load_older
        snapshot%u_older = self%u_older
        snapshot%flow_older = self%flow_older
    end subroutine save_state

    !> The reference lengths follow from the flows: the snapshot's must be those, bit
    !> for bit (else it was written for another scene).
    subroutine restore_state(self, snapshot, error)
        class(friction_stepper_type), intent(inout) :: self
        type(restart_type), intent(in) :: snapshot
        type(error_type), allocatable, intent(out) :: error

        call restore_common(self, snapshot, stepper_friction, 'the restart file was written ' &
            // 'by a run without sliding passages, this scene has some', error, size(self%flow))
        if (allocated(error)) return
        self%flow = snapshot%flow
        self%mode = snapshot%mode
        self%have_old = snapshot%have_old
        self%load_old = snapshot%load_old
        self%u_old = snapshot%u_old
        self%flow_old = snapshot%flow_old
        self%have_older = snapshot%have_older
        self%set_repeated = snapshot%set_repeated
        self%load_older = snapshot%load_older
        self%u_older = snapshot%u_older
        self%flow_older = snapshot%flow_older
        ! Restarted from the initial state: its first load step starts all-stick, as in
        ! the run that wrote the file (docs/decisions.md, "The first load step from rest
        ! starts all-stick").
        self%from_initial = snapshot%step == 0
        ! Only a jump leaves a step after step 0 without a predictor state (accept).
        self%jumped = snapshot%step > 0 .and. .not. snapshot%have_old
        self%have_limits = .false.
        self%flow_trial = self%flow
        self%mode_trial = self%mode
    end subroutine restore_state

    subroutine finalize(self)
        type(friction_stepper_type), intent(inout) :: self
        call self%newton_full%destroy()
        call self%newton_elastic%destroy()
        call self%newton_sliding%destroy()
        if (associated(self%full)) deallocate(self%full)
        if (associated(self%sliding)) deallocate(self%sliding)
        if (associated(self%elastic)) deallocate(self%elastic)
    end subroutine finalize
end module yarnfort_contact_friction_stepper
