! SPDX-License-Identifier: MIT
!> Membrane strains and forces of a periodic cell (curve.csv and VTK field data).
!>
!> The cell's period vectors are a_j = Fc A_j, A_1 = L10 e_x, A_2 = L20 e_y the reference
!> periods, Fc = [[1 + e11, k], [0, 1 + e22]] with e11, e22 the engineering strains of the
!> periods' projections and k = p_disp * shear the simple shear: a1 = L1 e_x and
!> a2 = L20 (k e_x + (1 + e22) e_y). gamma12 = atan(k / (1 + e22)) is the change of the
!> angle between them (rad). A node that follows a periodic image sits at its root plus
!> sum_j m_j a_j (m_j = lattice_j / L_j0), so the net's energy U changes with the periods
!> by the forces conjugate to them,
!>     F_j = dU/da_j = sum over nodes of m_j * (the net's force on the node),
!> and under any in-plane rate of deformation L of the cell (da_j = L a_j)
!>     dU = sum_j F_j . L a_j = A N : L,   A N = sum_j F_j (x) a_j,   A = |a1 x a2|.
!> N is the membrane force (N/m, per unit current length of the cut it acts across):
!> n11 = N_xx, n22 = N_yy, n12 = (N_xy + N_yx) / 2 (the two agree at equilibrium). With
!> the virial V = sum over nodes of force (x) reference lattice vector (F_j = V e_j / L_j0),
!> A N = V Fc^T, and the work of N is dW = A N : dFc Fc^-1 = V : dFc, i.e.
!>     dW = A0 [(1 + e22) n11 de11 + (1 + e11) n22 de22 + n12 ((1 + e11) dk - k de11)].
!> The shear in the yarns' frame, tau = F1y / |a2| = n12 cos(gamma12) - n22 sin(gamma12)
!> (moment balance), is the force across the cut along a2 normal to a1: zero when the
!> cell carries tension along its periods only (F_j parallel to a_j), as a pin-jointed
!> net does.
module yarnfort_output_membrane
    use yarnfort_kinds, only: wp
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_solver_state, only: step_state_type
    implicit none
    private

    public :: membrane_names, get_membrane, get_frame_shear

    !> The columns, in order: strains (1) and rad, then forces per width (N/m).
    character(len=*), parameter :: membrane_names(6) = [character(len=7) :: &
        'e11', 'e22', 'gamma12', 'n11', 'n22', 'n12']

contains

    !> e11, e22, gamma12, n11, n22, n12 of a periodic cell's state (see the module).
    pure function get_membrane(scene, state) result(values)
        type(scene_type), intent(in) :: scene
        type(step_state_type), intent(in) :: state
        real(wp) :: values(6)
        real(wp) :: strain(2), shear, deformation(2, 2), force(2, 2), area

        ! The periods follow the displacement channel, like every periodic link.
        strain = state%factors(scene%dofs%gap_channel) * scene%cell_strain
        shear = state%factors(scene%dofs%gap_channel) * scene%cell_shear
        ! A force-controlled period has its strain (e11, e22) as its own channel's factor.
        if (scene%lateral_channel > 0) strain(2) = state%factors(scene%lateral_channel)
        if (scene%axial_channel > 0) strain(1) = state%factors(scene%axial_channel)
        deformation = reshape([1.0_wp + strain(1), 0.0_wp, shear, 1.0_wp + strain(2)], [2, 2])
        area = product(scene%cell_period * [deformation(1, 1), deformation(2, 2)])
        ! A N = V Fc^T: the virial sums force (x) reference lattice vector.
        force = matmul(state%virial(1:2, 1:2), transpose(deformation))
        values(1:2) = strain
        values(3) = atan2(shear, deformation(2, 2))
        values(4) = force(1, 1) / area
        values(5) = force(2, 2) / area
        values(6) = 0.5_wp * (force(1, 2) + force(2, 1)) / area
    end function get_membrane

    !> The shear force in the yarns' frame (N/m) of get_membrane's values (see the module).
    pure real(wp) function get_frame_shear(values) result(tau)
        real(wp), intent(in) :: values(6)
        tau = values(6) * cos(values(3)) - values(5) * sin(values(3))
    end function get_frame_shear

end module yarnfort_output_membrane
