!> The door of the impulse problem (fortran/impulse.f90, docs/impulse.md) for the C
!> integrators (c/martello_internal.h, "the impulse problem"). The m contacts of a problem are
!> list[0..m) of the integrator's contact rows (martello_rows: contact j's penetration row
!> G_j, 0-based terms first[j] … first[j + 1] − 1 of node and coef) and its column
!> C_j = M⁻¹ B_jᵀ (length n) is column col[j] of the column-major array cols; the gap rate is
!> ġ_j = B_j v with B_j = −G_j (v_b − v_a for a node pair). Matrices are m × m, column-major.
module martello_api_impulse
   use, intrinsic :: iso_c_binding
   use martello_kinds, only: dp
   use martello_status
   use martello_impulse
   use martello_element_rows, only: rows_t, rows_init, rows_append
   implicit none
   private

   !> The C integrators' rows (c/martello_internal.h, martello_rows): three arrays.
   type, bind(C) :: c_rows_t
      type(c_ptr) :: first, node, coef
   end type c_rows_t

   !> The problem's contacts in the module's terms: rows B_k = −G_k (1-based nodes), columns.
   type :: problem_t
      type(rows_t) :: b
      integer, allocatable :: ic(:), k(:)
   end type problem_t

contains

   integer(c_int) function c_impulse_delassus(n, m, list, rows, col, cols, w) &
      bind(C, name='martello_impulse_delassus')
      integer(c_int), value :: n, m
      integer(c_int), intent(in) :: list(*), col(*)
      type(c_rows_t), intent(in) :: rows
      real(c_double), intent(in) :: cols(n, *)
      real(c_double), intent(out) :: w(m, *)
      type(problem_t) :: pb
      c_impulse_delassus = status_of_sizes(n, m)
      if (c_impulse_delassus /= MARTELLO_OK .or. m == 0) return
      pb = problem(m, list, rows, col)
      call delassus_columns(pb%b, pb%k, cols(:, pb%ic), w(:, 1:m))
   end function c_impulse_delassus

   integer(c_int) function c_impulse_newton(n, m, list, rows, col, cols, e, v, p, iterations) &
      bind(C, name='martello_impulse_newton')
      integer(c_int), value :: n, m
      integer(c_int), intent(in) :: list(*), col(*)
      type(c_rows_t), intent(in) :: rows
      real(c_double), intent(in) :: cols(n, *), e(*)
      real(c_double), intent(inout) :: v(*)
      real(c_double), intent(out) :: p(*)
      integer(c_int), intent(out) :: iterations
      type(problem_t) :: pb
      real(dp) :: w(m, m), g(m)
      integer :: info, its
      iterations = 0
      c_impulse_newton = status_of_sizes(n, m)
      if (c_impulse_newton /= MARTELLO_OK .or. m == 0) return
      pb = problem(m, list, rows, col)
      call delassus_columns(pb%b, pb%k, cols(:, pb%ic), w)
      g = rates(pb, v(1:n))
      p(1:m) = 0.0_dp
      call newton_impulses(g, min(g, 0.0_dp), e(1:m), p(1:m), info, its, w=w)   ! an impact
      iterations = its
      c_impulse_newton = martello_status_of(info)
      if (info == IMPULSE_OK) call apply_impulses(cols(:, pb%ic), p(1:m), v(1:n))
   end function c_impulse_newton

   integer(c_int) function c_impulse_contact_forces(n, m, list, rows, col, cols, acc, lam, held, &
                                                    iterations) bind(C, name='martello_impulse_contact_forces')
      integer(c_int), value :: n, m
      integer(c_int), intent(in) :: list(*), col(*)
      type(c_rows_t), intent(in) :: rows
      real(c_double), intent(in) :: cols(n, *), acc(*)
      real(c_double), intent(out) :: lam(*)
      integer(c_int), intent(out) :: held(*), iterations
      type(problem_t) :: pb
      real(dp) :: w(m, m)
      logical :: keep(m)
      integer :: info, its
      iterations = 0
      c_impulse_contact_forces = status_of_sizes(n, m)
      if (c_impulse_contact_forces /= MARTELLO_OK .or. m == 0) return
      pb = problem(m, list, rows, col)
      call delassus_columns(pb%b, pb%k, cols(:, pb%ic), w)
      call contact_forces(w, rates(pb, acc(1:n)), lam(1:m), keep, info, its)
      held(1:m) = merge(1, 0, keep)
      iterations = its
      c_impulse_contact_forces = martello_status_of(info)
   end function c_impulse_contact_forces

   integer(c_int) function c_impulse_factor(n, m, list, rows, col, cols, l) &
      bind(C, name='martello_impulse_factor')
      integer(c_int), value :: n, m
      integer(c_int), intent(in) :: list(*), col(*)
      type(c_rows_t), intent(in) :: rows
      real(c_double), intent(in) :: cols(n, *)
      real(c_double), intent(out) :: l(m, *)
      type(problem_t) :: pb
      integer :: info
      c_impulse_factor = status_of_sizes(n, m)
      if (c_impulse_factor /= MARTELLO_OK .or. m == 0) return
      pb = problem(m, list, rows, col)
      call delassus_columns(pb%b, pb%k, cols(:, pb%ic), l(:, 1:m))
      call delassus_factor(l(:, 1:m), info)
      c_impulse_factor = martello_status_of(info)
   end function c_impulse_factor

   integer(c_int) function c_impulse_project(n, m, list, rows, col, cols, l, target, x, p) &
      bind(C, name='martello_impulse_project')
      integer(c_int), value :: n, m
      integer(c_int), intent(in) :: list(*), col(*)
      type(c_rows_t), intent(in) :: rows
      real(c_double), intent(in) :: cols(n, *), l(m, *)
      type(c_ptr), value :: target
      real(c_double), intent(inout) :: x(*)
      real(c_double), intent(out) :: p(*)
      type(problem_t) :: pb
      real(c_double), pointer :: tg(:)
      real(dp) :: goal(m)
      c_impulse_project = status_of_sizes(n, m)
      if (c_impulse_project /= MARTELLO_OK .or. m == 0) return
      pb = problem(m, list, rows, col)
      goal = 0.0_dp
      if (c_associated(target)) then
         call c_f_pointer(target, tg, [m])
         goal = tg
      end if
      call project_factored(pb%b, pb%k, cols(:, pb%ic), l(:, 1:m), goal, x(1:n), p(1:m))
   end function c_impulse_project

   integer(c_int) function c_impulse_accumulation(e, s, a, da, t, t_res, d_res, v_res, restarts, &
                                                  t_inf) bind(C, name='martello_impulse_accumulation')
      real(c_double), value :: e, s, a, da, t, t_res, d_res, v_res
      integer(c_int), value :: restarts
      real(c_double), intent(out) :: t_inf
      logical :: acc
      call impulse_accumulation(e, s, a, da, t, t_res, d_res, v_res, restarts /= 0, acc, t_inf)
      c_impulse_accumulation = merge(1, 0, acc)
   end function c_impulse_accumulation

   !> Contacts list[0..m) of the rows (with col) in the module's terms. A few integers a
   !> contact, next to the m × m matrices the doors hold on the stack: no status to return
   !> from inside an expression, so a failed allocation stops with the out-of-memory line.
   function problem(m, list, rows, col) result(pb)
      integer, intent(in) :: m
      integer(c_int), intent(in) :: list(*), col(*)
      type(c_rows_t), intent(in) :: rows
      type(problem_t) :: pb
      integer(c_int), pointer :: first(:), node(:)
      real(c_double), pointer :: coef(:)
      integer :: st, k, lo, hi, top, nt
      top = maxval(list(1:m)) + 2
      call c_f_pointer(rows%first, first, [top])
      nt = 0
      do k = 1, m
         nt = max(nt, first(list(k) + 2))
      end do
      call c_f_pointer(rows%node, node, [max(nt, 1)])
      call c_f_pointer(rows%coef, coef, [max(nt, 1)])
      allocate (pb%ic(m), pb%k(m), stat=st)
      if (st == 0) call rows_init(pb%b, m, 2, st)
      do k = 1, m
         if (st /= 0) exit
         lo = first(list(k) + 1) + 1; hi = first(list(k) + 2)
         call rows_append(pb%b, node(lo:hi) + 1, -coef(lo:hi), st)
      end do
      if (st /= 0) call out_of_memory('the impulse problem', (3*INT_BYTES + REAL_BYTES)*m, FIX_SMALLER_SCENE)
      pb%ic = col(list(1:m) + 1) + 1
      pb%k = [(k, k = 1, m)]
   end function problem

   !> ġ_k = B_k x of the problem's contacts.
   pure function rates(pb, x) result(g)
      type(problem_t), intent(in) :: pb
      real(dp), intent(in) :: x(:)
      real(dp) :: g(size(pb%k))
      integer :: k
      do k = 1, size(pb%k)
         g(k) = b_dot(pb%b, k, x)
      end do
   end function rates

   pure integer function status_of_sizes(n, m)
      integer(c_int), intent(in) :: n, m
      status_of_sizes = merge(MARTELLO_OK, MARTELLO_ERR_ARGUMENT, n >= 0 .and. m >= 0)
   end function status_of_sizes

   elemental integer function martello_status_of(info)
      integer, intent(in) :: info
      select case (info)
      case (IMPULSE_OK); martello_status_of = MARTELLO_OK
      case (IMPULSE_INFEASIBLE, IMPULSE_SINGULAR); martello_status_of = MARTELLO_ERR_SINGULAR
      case (IMPULSE_NO_MEMORY); martello_status_of = MARTELLO_ERR_MEMORY
      case default; martello_status_of = MARTELLO_ERR_NOT_CONVERGED
      end select
   end function martello_status_of
end module martello_api_impulse
