! SPDX-License-Identifier: MIT
!> bind(C) interfaces to cholmod_shim.c (an opaque handle around CHOLMOD's 64-bit
!> `cholmod_l_*` API, see the comment there for why a shim is used) and the CHOLMOD
!> status codes of cholmod_core.h. Only yarnfort_linalg_backend_cholmod uses this module, and
!> yarnfort_linalg_composite_lu_choice its METIS order.
module yarnfort_linalg_binding_cholmod
    use, intrinsic :: iso_c_binding, only: c_int, c_long, c_double, c_ptr
    implicit none
    private

    public :: cholmod_ok, cholmod_not_posdef, cholmod_dsmall, cholmod_not_installed
    public :: cholmod_out_of_memory, cholmod_too_large, cholmod_invalid
    public :: cholmod_gpu_problem, cholmod_no_handle
    public :: yarnfort_cholmod_create, yarnfort_cholmod_free, yarnfort_cholmod_analyze
    public :: yarnfort_cholmod_factorize, yarnfort_cholmod_solve
    public :: yarnfort_cholmod_metis_order

    !> CHOLMOD status codes (cholmod_core.h); warnings are positive, errors negative.
    integer(c_int), parameter :: cholmod_ok = 0, cholmod_not_posdef = 1, cholmod_dsmall = 2
    integer(c_int), parameter :: cholmod_not_installed = -1, cholmod_out_of_memory = -2, &
        cholmod_too_large = -3, cholmod_invalid = -4, cholmod_gpu_problem = -5
    !> Shim status: the handle is missing (YARNFORT_CHOLMOD_NO_HANDLE in cholmod_shim.c).
    integer(c_int), parameter :: cholmod_no_handle = -100

    interface
        !> New handle (CHOLMOD started, print level 0, LL' factor, supernodal from
        !> `supernodal_switch` flops per nonzero of L); NULL on failure.
        function yarnfort_cholmod_create(supernodal_switch) result(handle) &
                bind(C, name='yarnfort_cholmod_create')
            import :: c_ptr, c_double
            real(c_double), value :: supernodal_switch
            type(c_ptr) :: handle
        end function yarnfort_cholmod_create

        !> Free everything the handle owns and the handle itself; NULL is ignored.
        subroutine yarnfort_cholmod_free(handle) bind(C, name='yarnfort_cholmod_free')
            import :: c_ptr
            type(c_ptr), value :: handle
        end subroutine yarnfort_cholmod_free

        !> Ordering and symbolic factorisation of the upper triangle of the pattern.
        function yarnfort_cholmod_analyze(handle, n, col_ptr, row_index) result(status) &
                bind(C, name='yarnfort_cholmod_analyze')
            import :: c_int, c_long, c_ptr
            type(c_ptr), value :: handle
            integer(c_long), value :: n
            integer(c_long), intent(in) :: col_ptr(*), row_index(*)
            integer(c_int) :: status
        end function yarnfort_cholmod_analyze

        !> Numeric LL' factorisation of the values of the analysed pattern; minor is the
        !> 0-based failed column in the fill-reducing order, or n.
        function yarnfort_cholmod_factorize(handle, n, values, minor) &
                result(status) bind(C, name='yarnfort_cholmod_factorize')
            import :: c_int, c_long, c_double, c_ptr
            type(c_ptr), value :: handle
            integer(c_long), value :: n
            real(c_double), intent(in) :: values(*)
            integer(c_long), intent(out) :: minor
            integer(c_int) :: status
        end function yarnfort_cholmod_factorize

        !> Overwrite rhs (n x ncol, column-major) with the solution of A X = rhs.
        function yarnfort_cholmod_solve(handle, n, ncol, rhs) result(status) &
                bind(C, name='yarnfort_cholmod_solve')
            import :: c_int, c_long, c_double, c_ptr
            type(c_ptr), value :: handle
            integer(c_long), value :: n, ncol
            real(c_double), intent(inout) :: rhs(*)
            integer(c_int) :: status
        end function yarnfort_cholmod_solve

        !> METIS' order of A + A^T (0-based, postordered) and the nonzeros of the Cholesky
        !> factor of A + A^T in that order, diagonal included.
        function yarnfort_cholmod_metis_order(n, col_ptr, row_index, perm, lnz) &
                result(status) bind(C, name='yarnfort_cholmod_metis_order')
            import :: c_int, c_long, c_double
            integer(c_long), value :: n
            integer(c_long), intent(in) :: col_ptr(*), row_index(*)
            integer(c_long), intent(out) :: perm(*)
            real(c_double), intent(out) :: lnz
            integer(c_int) :: status
        end function yarnfort_cholmod_metis_order
    end interface

end module yarnfort_linalg_binding_cholmod
