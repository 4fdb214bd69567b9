! SPDX-License-Identifier: MIT
!> Global assembly: internal forces, residual and sparse Jacobian of the equilibrium
!> equations (paper eq. 46 with constraints eliminated, eqs. 51-52).
module yarnfort_assembly_assemble
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_text, only: format_short
    use yarnfort_scene_scene, only: scene_type, get_applied_force
    use yarnfort_assembly_truss, only: get_truss_response
    use yarnfort_assembly_pattern, only: pattern_type
    implicit none
    private

    public :: assemble_internal_force, assemble_residual, assemble_jacobian
    public :: add_element_tangents

    !> Elements shorter than this fraction of their reference length are degenerate.
    real(wp), parameter :: degenerate_length_ratio = 1.0e-12_wp

contains

    !> Internal force (gradient of the elastic energy) at every coordinate, (3*n_nodes),
    !> and each element's tension and stretch, for node positions x (3, n_nodes) and
    !> element reference lengths length0. `spring`: weight of the regularising spring
    !> (get_truss_tension) of a Newton predictor; absent or 0 for the exact law.
    !> `stiffness_cap`: that of get_truss_tension (another predictor); absent: none.
    subroutine assemble_internal_force(scene, x, length0, internal, tension, stretch, error, &
            spring, rounding, stiffness_cap)
        type(scene_type), intent(in) :: scene
        real(wp), intent(in) :: x(:, :), length0(:)
        real(wp), intent(out) :: internal(:), tension(:), stretch(:)
        type(error_type), allocatable, intent(out) :: error
        real(wp), intent(in), optional :: spring, stiffness_cap
        !> Each tension's rounding error (get_tension_rounding), for the row levels.
        real(wp), intent(out), optional :: rounding(:)
        integer :: e, n1, n2, n
        real(wp) :: force(3), weight
        real(wp), allocatable :: position_norm(:)

        weight = 0.0_wp
        if (present(spring)) weight = spring
        internal = 0.0_wp
        ! Each node's |x| once, not once per element at it (the roundings' r).
        if (present(rounding)) position_norm = [(norm2(x(:, n)), n = 1, size(x, 2))]
        do e = 1, scene%network%n_elements()
            n1 = scene%network%element_nodes(1, e)
            n2 = scene%network%element_nodes(2, e)
            if (present(rounding)) then
                call get_element_response(scene, x, length0, e, weight, tension(e), stretch(e), &
                    force, error, rounding=rounding(e), &
                    position_norm=position_norm(n1) + position_norm(n2), &
                    stiffness_cap=stiffness_cap)
            else
                call get_element_response(scene, x, length0, e, weight, tension(e), stretch(e), &
                    force, error, stiffness_cap=stiffness_cap)
            end if
            if (allocated(error)) return
            if (.not. ieee_is_finite(tension(e))) then
                call overflow(e, stretch(e))
                return
            end if
            internal(3 * n1 - 2:3 * n1) = internal(3 * n1 - 2:3 * n1) - force
            internal(3 * n2 - 2:3 * n2) = internal(3 * n2 - 2:3 * n2) + force
        end do
    contains
        subroutine overflow(element, element_stretch)
            integer, intent(in) :: element
            real(wp), intent(in) :: element_stretch
            character(len=200) :: buffer
            write(buffer, '("element ", i0, " (material ''", a, "''): its tension at stretch ", &
                &a, " is not a finite number (the force law''s scale is too large ", &
                &"for double precision)")') element, &
                trim(scene%laws(scene%network%element_material(element))%name), &
                format_short(element_stretch, 4)
            call fatal_error(error, trim(buffer))
        end subroutine overflow
    end subroutine assemble_internal_force

    !> Residual on the unknowns: P^T (internal - applied force at the channels' factors);
    !> `spring` and `stiffness_cap` as for assemble_internal_force.
    subroutine assemble_residual(scene, x, length0, factors, residual, error, spring, &
            stiffness_cap)
        type(scene_type), intent(in) :: scene
        real(wp), intent(in) :: x(:, :), length0(:), factors(:)
        real(wp), intent(out) :: residual(:)
        type(error_type), allocatable, intent(out) :: error
        real(wp), intent(in), optional :: spring, stiffness_cap
        real(wp), allocatable :: internal(:), tension(:), stretch(:), applied(:)

        allocate(internal(size(scene%external_force, 1)), applied(size(scene%external_force, 1)))
        allocate(tension(scene%network%n_elements()), stretch(scene%network%n_elements()))
        call assemble_internal_force(scene, x, length0, internal, tension, stretch, error, &
            spring, stiffness_cap=stiffness_cap)
        if (allocated(error)) return
        call get_applied_force(scene, factors, applied)
        call scene%dofs%gather(internal - applied, residual)
    end subroutine assemble_residual

    !> Jacobian values P^T K P in the slots of `pattern` (values are overwritten);
    !> `spring`, `tangent_spring` and `stiffness_cap` as for add_element_tangents.
    subroutine assemble_jacobian(scene, pattern, x, length0, values, error, spring, &
            tangent_spring, stiffness_cap)
        type(scene_type), intent(in) :: scene
        type(pattern_type), intent(in) :: pattern
        real(wp), intent(in) :: x(:, :), length0(:)
        real(wp), intent(out) :: values(:)
        type(error_type), allocatable, intent(out) :: error
        real(wp), intent(in), optional :: spring, tangent_spring, stiffness_cap

        values = 0.0_wp
        call add_element_tangents(scene, pattern%element_slot, x, length0, values, error, &
            spring, tangent_spring, stiffness_cap=stiffness_cap)
    end subroutine assemble_jacobian

    !> Add every element's 6x6 tangent to `values` at element_slot(a, b, e) (entries
    !> a, b <= 6 of each element's slot table: node 1 xyz, node 2 xyz; 0 = skip).
    !> `spring`: the regularising spring in the model (predictor solves); `tangent_spring`:
    !> the spring in the tangent of slack strings only (get_truss_response). Both absent:
    !> the exact tangent of the exact law. `dforce_dlength0` (3, n_elements): each
    !> element's derivative of its node-2 force with respect to L0, from the same
    !> evaluation (for the flows of sliding contact). `stiffness_cap` as for
    !> assemble_internal_force.
    subroutine add_element_tangents(scene, element_slot, x, length0, values, error, spring, &
            tangent_spring, dforce_dlength0, stiffness_cap)
        type(scene_type), intent(in) :: scene
        integer, intent(in) :: element_slot(:, :, :)
        real(wp), intent(in) :: x(:, :), length0(:)
        real(wp), intent(inout) :: values(:)
        type(error_type), allocatable, intent(out) :: error
        real(wp), intent(in), optional :: spring, tangent_spring, stiffness_cap
        real(wp), intent(out), optional :: dforce_dlength0(:, :)
        integer :: e, a, b, slot
        real(wp) :: force(3), block(3, 3), tension, stretch, sign_ab, weight, tangent_weight

        weight = 0.0_wp
        if (present(spring)) weight = spring
        tangent_weight = 0.0_wp
        if (present(tangent_spring)) tangent_weight = tangent_spring

        do e = 1, scene%network%n_elements()
            if (present(dforce_dlength0)) then
                call get_element_response(scene, x, length0, e, weight, tension, stretch, &
                    force, error, block, tangent_weight, dforce_dlength0=dforce_dlength0(:, e), &
                    stiffness_cap=stiffness_cap)
            else
                call get_element_response(scene, x, length0, e, weight, tension, stretch, &
                    force, error, block, tangent_weight, stiffness_cap=stiffness_cap)
            end if
            if (allocated(error)) return
            do b = 1, 6
                do a = 1, 6
                    slot = element_slot(a, b, e)
                    if (slot == 0) cycle
                    sign_ab = merge(1.0_wp, -1.0_wp, (a <= 3) .eqv. (b <= 3))
                    values(slot) = values(slot) + sign_ab * block(mod(a - 1, 3) + 1, mod(b - 1, 3) + 1)
                end do
            end do
        end do
    end subroutine add_element_tangents

    !> Element e's response (get_truss_response: tension, stretch, force on node 2 and,
    !> with `block`, its tangent; `spring`, `tangent_spring` as there) at node positions x,
    !> after checking that it has not degenerated to a point.
    subroutine get_element_response(scene, x, length0, e, spring, tension, stretch, force, &
            error, block, tangent_spring, rounding, dforce_dlength0, position_norm, &
            stiffness_cap)
        type(scene_type), intent(in) :: scene
        real(wp), intent(in) :: x(:, :), length0(:)
        integer, intent(in) :: e
        real(wp), intent(in) :: spring
        real(wp), intent(out) :: tension, stretch, force(3)
        type(error_type), allocatable, intent(out) :: error
        real(wp), intent(out), optional :: block(3, 3)
        real(wp), intent(in), optional :: tangent_spring
        real(wp), intent(out), optional :: rounding, dforce_dlength0(3)
        !> norm2 of the element's two node positions, summed (for `rounding`).
        real(wp), intent(in), optional :: position_norm
        real(wp), intent(in), optional :: stiffness_cap
        real(wp) :: length
        character(len=160) :: buffer

        associate(x1 => x(:, scene%network%element_nodes(1, e)), &
                x2 => x(:, scene%network%element_nodes(2, e)))
            length = norm2(x2 - x1)
            if (.not. (length > degenerate_length_ratio * length0(e))) then
                write(buffer, '("element ", i0, " (nodes ", i0, ", ", i0, ") has length ", &
                    & a)') e, scene%network%element_nodes(:, e), format_short(length, 4)
                call fatal_error(error, trim(buffer))
                return
            end if
            call get_truss_response(scene%laws(scene%network%element_material(e))%law, spring, &
                length0(e), x1, x2, tension, stretch, force, block, tangent_spring, rounding, &
                dforce_dlength0, length, position_norm, stiffness_cap)
        end associate
    end subroutine get_element_response

end module yarnfort_assembly_assemble
