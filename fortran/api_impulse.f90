!> The door of the impulse problem (fortran/impulse.f90, docs/impulse.md) for the C
!> integrators (c/martello_internal.h, "the impulse problem"). Contacts k = 0..m−1 join the
!> 0-based nodes a[k] and b[k] (−1: the ground); their columns C_k = M⁻¹ B_kᵀ (length n) are
!> column col[k] of the column-major array cols; the gap rate is ġ_k = B_k v = v_b − v_a.
!> Matrices are m × m, column-major.
module martello_api_impulse
   use, intrinsic :: iso_c_binding
   use martello_kinds, only: dp
   use martello_status
   use martello_impulse
   implicit none
   private

contains

   integer(c_int) function c_impulse_delassus(n, m, a, b, cols, col, w) &
      bind(C, name='martello_impulse_delassus')
      integer(c_int), value :: n, m
      integer(c_int), intent(in) :: a(*), b(*), col(*)
      real(c_double), intent(in) :: cols(n, *)
      real(c_double), intent(out) :: w(m, *)
      c_impulse_delassus = MARTELLO_ERR_ARGUMENT
      if (n < 0 .or. m < 0) return
      call delassus_columns(side(a, m), side(b, m), cols(:, col(1:m) + 1), w(:, 1:m))
      c_impulse_delassus = MARTELLO_OK
   end function c_impulse_delassus

   integer(c_int) function c_impulse_newton(n, m, a, b, cols, col, e, v, p, iterations) &
      bind(C, name='martello_impulse_newton')
      integer(c_int), value :: n, m
      integer(c_int), intent(in) :: a(*), b(*), col(*)
      real(c_double), intent(in) :: cols(n, *), e(*)
      real(c_double), intent(inout) :: v(*)
      real(c_double), intent(out) :: p(*)
      integer(c_int), intent(out) :: iterations
      real(dp) :: w(m, m), g(m)
      integer :: info, its
      c_impulse_newton = MARTELLO_ERR_ARGUMENT
      iterations = 0
      if (n < 0 .or. m < 0) return
      c_impulse_newton = MARTELLO_OK
      if (m == 0) return
      call delassus_columns(side(a, m), side(b, m), cols(:, col(1:m) + 1), w)
      g = rates(a, b, m, v(1:n))
      p(1:m) = 0.0_dp
      call newton_impulses(w, g, min(g, 0.0_dp), e(1:m), p(1:m), info, its)   ! an impact
      iterations = its
      c_impulse_newton = martello_status_of(info)
      if (info /= IMPULSE_OK) return
      call apply_impulses(cols(:, col(1:m) + 1), p(1:m), v(1:n))
   end function c_impulse_newton

   integer(c_int) function c_impulse_contact_forces(n, m, a, b, cols, col, acc, lam, held, &
                                                    iterations) bind(C, name='martello_impulse_contact_forces')
      integer(c_int), value :: n, m
      integer(c_int), intent(in) :: a(*), b(*), col(*)
      real(c_double), intent(in) :: cols(n, *), acc(*)
      real(c_double), intent(out) :: lam(*)
      integer(c_int), intent(out) :: held(*), iterations
      real(dp) :: w(m, m)
      logical :: keep(m)
      integer :: info, its
      c_impulse_contact_forces = MARTELLO_ERR_ARGUMENT
      iterations = 0
      if (n < 0 .or. m < 0) return
      c_impulse_contact_forces = MARTELLO_OK
      if (m == 0) return
      call delassus_columns(side(a, m), side(b, m), cols(:, col(1:m) + 1), w)
      call contact_forces(w, rates(a, b, m, acc(1:n)), lam(1:m), keep, info, its)
      held(1:m) = merge(1, 0, keep)
      iterations = its
      c_impulse_contact_forces = martello_status_of(info)
   end function c_impulse_contact_forces

   integer(c_int) function c_impulse_factor(n, m, a, b, cols, col, l) &
      bind(C, name='martello_impulse_factor')
      integer(c_int), value :: n, m
      integer(c_int), intent(in) :: a(*), b(*), col(*)
      real(c_double), intent(in) :: cols(n, *)
      real(c_double), intent(out) :: l(m, *)
      integer :: info
      c_impulse_factor = MARTELLO_ERR_ARGUMENT
      if (n < 0 .or. m < 0) return
      call delassus_columns(side(a, m), side(b, m), cols(:, col(1:m) + 1), l(:, 1:m))
      call delassus_factor(l(:, 1:m), info)
      c_impulse_factor = martello_status_of(info)
   end function c_impulse_factor

   integer(c_int) function c_impulse_project(n, m, a, b, cols, col, l, target, x, p) &
      bind(C, name='martello_impulse_project')
      integer(c_int), value :: n, m
      integer(c_int), intent(in) :: a(*), b(*), col(*)
      real(c_double), intent(in) :: cols(n, *), l(m, *)
      type(c_ptr), value :: target
      real(c_double), intent(inout) :: x(*)
      real(c_double), intent(out) :: p(*)
      real(c_double), pointer :: tg(:)
      real(dp) :: zero(m)
      c_impulse_project = MARTELLO_ERR_ARGUMENT
      if (n < 0 .or. m < 0) return
      c_impulse_project = MARTELLO_OK
      if (m == 0) return
      if (c_associated(target)) then
         call c_f_pointer(target, tg, [m])
         call project_factored(side(a, m), side(b, m), cols(:, col(1:m) + 1), l(:, 1:m), tg, &
                               x(1:n), p(1:m))
      else
         zero = 0.0_dp
         call project_factored(side(a, m), side(b, m), cols(:, col(1:m) + 1), l(:, 1:m), zero, &
                               x(1:n), p(1:m))
      end if
   end function c_impulse_project

   integer(c_int) function c_impulse_accumulation(e, s, a, t, tau_res, height_res, t_inf) &
      bind(C, name='martello_impulse_accumulation')
      real(c_double), value :: e, s, a, t, tau_res, height_res
      real(c_double), intent(out) :: t_inf
      logical :: acc
      call impulse_accumulation(e, s, a, t, tau_res, height_res, acc, t_inf)
      c_impulse_accumulation = merge(1, 0, acc)
   end function c_impulse_accumulation

   !> 0-based nodes (−1: ground) to the module's 1-based sides (0: ground).
   pure function side(node, m) result(s)
      integer(c_int), intent(in) :: node(*)
      integer, intent(in) :: m
      integer :: s(m)
      s = max(node(1:m), -1) + 1
   end function side

   !> ġ_k = x_b − x_a of the m contacts.
   pure function rates(a, b, m, x) result(g)
      integer(c_int), intent(in) :: a(*), b(*)
      integer, intent(in) :: m
      real(dp), intent(in) :: x(:)
      real(dp) :: g(m)
      integer :: k
      do k = 1, m
         g(k) = at(b(k)) - at(a(k))
      end do
   contains
      pure real(dp) function at(node)
         integer(c_int), intent(in) :: node
         at = 0.0_dp
         if (node >= 0) at = x(node + 1)
      end function at
   end function rates

   elemental integer function martello_status_of(info)
      integer, intent(in) :: info
      select case (info)
      case (IMPULSE_OK); martello_status_of = MARTELLO_OK
      case (IMPULSE_INFEASIBLE, IMPULSE_SINGULAR); martello_status_of = MARTELLO_ERR_SINGULAR
      case default; martello_status_of = MARTELLO_ERR_NOT_CONVERGED
      end select
   end function martello_status_of
end module martello_api_impulse
