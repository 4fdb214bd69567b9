! SPDX-License-Identifier: MIT
!> Membrane strains and forces of a periodic cell (curve.csv and VTK field data).
!>
!> The cell's period vectors are a1 = L1 e_x and a2 = L2 e_y, L_k = L_k0 (1 + e_kk) with
!> e11, e22 the engineering strains of the periods; gamma12 is the change of the angle
!> between them (0: the periods stay along x and y). A node that follows a periodic
!> image sits at its root plus sum_j m_j a_j (m_j = lattice_j / L_j0), so the net's energy
!> U changes with the periods by the forces conjugate to them,
!>     F_j = dU/da_j = sum over nodes of m_j * (the net's force on the node),
!> and under any in-plane rate of deformation L of the cell (da_j = L a_j)
!>     dU = sum_j F_j . L a_j = A N : L,   A N = sum_j F_j (x) a_j,   A = L1 L2.
!> N is the membrane force (N/m): n11 = N_xx = F_1x / L2 (the x force across a
!> y-parallel edge per unit current edge length), n22 = N_yy = F_2y / L1, and
!> n12 = (N_xy + N_yx) / 2 = (F_2x / L1 + F_1y / L2) / 2 (the two agree at equilibrium).
!> The work of N is dW = A0 [(1 + e22) n11 de11 + (1 + e11) n22 de22] (A0 = L10 L20).
module yarnfort_output_membrane
    use yarnfort_kinds, only: wp
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_solver_state, only: step_state_type
    implicit none
    private

    public :: membrane_names, get_membrane

    !> The columns, in order: strains (1) and rad, then forces per width (N/m).
    character(len=*), parameter :: membrane_names(6) = [character(len=7) :: &
        'e11', 'e22', 'gamma12', 'n11', 'n22', 'n12']

contains

    !> e11, e22, gamma12, n11, n22, n12 of a periodic cell's state (see the module).
    pure function get_membrane(scene, state) result(values)
        type(scene_type), intent(in) :: scene
        type(step_state_type), intent(in) :: state
        real(wp) :: values(6)
        real(wp) :: strain(2), stretch(2), area

        ! The periods follow the displacement channel, like every periodic link.
        strain = state%factors(scene%dofs%gap_channel) * scene%cell_strain
        ! A force-controlled period has its strain (e11, e22) as its own channel's factor.
        if (scene%lateral_channel > 0) strain(2) = state%factors(scene%lateral_channel)
        if (scene%axial_channel > 0) strain(1) = state%factors(scene%axial_channel)
        stretch = 1.0_wp + strain
        area = product(scene%cell_period * stretch)
        ! N_kl = virial_kl (1 + e_l) / A: the virial sums force (x) reference lattice vector.
        values(1:2) = strain
        values(3) = 0.0_wp
        values(4) = state%virial(1, 1) * stretch(1) / area
        values(5) = state%virial(2, 2) * stretch(2) / area
        values(6) = 0.5_wp * (state%virial(1, 2) * stretch(2) + state%virial(2, 1) &
            * stretch(1)) / area
    end function get_membrane

end module yarnfort_output_membrane
