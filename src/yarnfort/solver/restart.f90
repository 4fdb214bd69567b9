! SPDX-License-Identifier: MIT
!> A restart snapshot: everything the continuation and the load stepper need to go on
!> from a converged step exactly as an uninterrupted run would. Filled after every
!> converged step (yarnfort_solver_continuation), written to and read from the output
!> folder by yarnfort_output_restart_file.
module yarnfort_solver_restart
    use yarnfort_kinds, only: wp
    implicit none
    private

    public :: restart_type, stepper_elastic, stepper_friction

    !> Which stepper filled the snapshot.
    character(len=*), parameter :: stepper_elastic = 'elastic'
    character(len=*), parameter :: stepper_friction = 'friction'

    type :: restart_type
        !> Fingerprint of the input the run was made with ('': unknown), and the scene's
        !> sizes: nodes, elements, position unknowns, sliding passages.
        character(len=16) :: input_hash = ''
        integer :: n_nodes = 0, n_elements = 0, n_unknowns = 0, n_passages = 0
        !> Continuation: the converged step, its pseudo-time, the next step size to try,
        !> the path knot the next step heads for, and the sum of the step's channel
        !> factors (for the loading direction of the next step).
        integer :: step = 0, knot = 2
        real(wp) :: time = 0.0_wp, next_step = 0.0_wp, previous_load = 0.0_wp
        !> Load stepper: `stepper_elastic` or `stepper_friction`.
        character(len=16) :: stepper = ''
        !> Accepted factors of the load channels, position unknowns and element
        !> reference lengths.
        real(wp), allocatable :: factors(:)
        real(wp), allocatable :: u(:), length0(:)
        !> Friction: flows and stick/slip mode of each passage; the accepted state before
        !> (position unknowns, flows, sum of the factors) for the secant predictor, valid
        !> when `have_old`.
        real(wp), allocatable :: flow(:)
        integer, allocatable :: mode(:)
        logical :: have_old = .false.
        real(wp) :: load_old = 0.0_wp
        !> Pseudo-time of the converged step before `step` (that of its curve row; the
        !> step's own time for step 0), so that load_old can be checked against the path.
        real(wp) :: time_old = 0.0_wp
        real(wp), allocatable :: u_old(:), flow_old(:)
        !> Friction: the accepted state before that (position unknowns, flows, sum of the
        !> factors) for the quadratic predictor, valid when `have_older`; `set_repeated`: the
        !> active set held over the last step.
        logical :: have_older = .false., set_repeated = .false.
        real(wp) :: load_older = 0.0_wp
        real(wp), allocatable :: u_older(:), flow_older(:)
        !> Force control (yarnfort_solver_force_control): the secant slope dn/de of the
        !> x and the y period's outer iteration (0: none yet, or not force-controlled).
        real(wp) :: held_slope(2) = 0.0_wp
    end type restart_type

end module yarnfort_solver_restart
