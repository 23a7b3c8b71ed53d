!> Elements as rows of the constraint operator (docs/buildings.md, "Contacts between plan
!> points"): element j (a contact or a link) deforms by
!>
!>    d_j = Σ_k coef_k x(node_k),   k = first(j) … first(j + 1) − 1,
!>
!> and its force f acts on the nodes as coef_k f (the transpose). A pair of nodes (a, b) is
!> the row (a, +1), (b, −1); a contact between plan points of two rigid floors has up to six
!> terms, n·(P_a q_a − P_b q_b). Ground terms are never stored (the ground does not move), so a
!> node-to-wall contact has one term and a row may have none. Every reader of an element's
!> nodes goes through this module: the forces and their tangents (assembly), the Delassus
!> operator W = G M⁻¹ Gᵀ (impulse, effective mass), the observer and the C integrators
!> (martello_model_topology).
module martello_element_rows
   use martello_kinds, only: dp
   implicit none
   private
   public :: rows_t, rows_init, rows_append, rows_append_pair, row_dot, row_dot1, row_add, row_stencil, &
      row_span, row_lo, row_hi, row_is_pair, row_pair, row_a, row_b, rows_terms, rows_move

   !> n rows in CSR form: row j's terms are first(j) … first(j + 1) − 1 of node and coef
   !> (first(1) = 1); the term arrays grow as rows are appended.
   type :: rows_t
      integer :: n = 0
      integer, allocatable :: first(:)
      integer, allocatable :: node(:)
      real(dp), allocatable :: coef(:)
   end type rows_t

contains

   !> Room for max_rows rows of about terms_each terms (the term arrays grow past that).
   subroutine rows_init(r, max_rows, terms_each, stat)
      type(rows_t), intent(out) :: r
      integer, intent(in) :: max_rows, terms_each
      integer, intent(out) :: stat
      allocate (r%first(max_rows + 1), r%node(max(1, terms_each*max_rows)), &
                r%coef(max(1, terms_each*max_rows)), stat=stat)
      if (stat /= 0) return
      r%n = 0; r%first(1) = 1
   end subroutine rows_init

   !> Append a row of the given terms (node 0, the ground, is left out; a node given twice has
   !> its coefficients summed). stat /= 0: the term arrays could not grow.
   subroutine rows_append(r, node, coef, stat)
      type(rows_t), intent(inout) :: r
      integer, intent(in) :: node(:)
      real(dp), intent(in) :: coef(:)
      integer, intent(out) :: stat
      integer :: k, p, q, at
      stat = 0
      at = r%first(r%n + 1)
      call grow(r, at + size(node) - 1, stat)
      if (stat /= 0) return
      q = at - 1
      terms: do k = 1, size(node)
         if (node(k) == 0) cycle
         do p = at, q
            if (r%node(p) == node(k)) then
               r%coef(p) = r%coef(p) + coef(k); cycle terms
            end if
         end do
         q = q + 1
         r%node(q) = node(k); r%coef(q) = coef(k)
      end do terms
      r%n = r%n + 1
      r%first(r%n + 1) = q + 1
   end subroutine rows_append

   !> Append the row of a node pair: (a, +1), (b, −1), either side 0 for the ground.
   subroutine rows_append_pair(r, a, b, stat)
      type(rows_t), intent(inout) :: r
      integer, intent(in) :: a, b
      integer, intent(out) :: stat
      call rows_append(r, [a, b], [1.0_dp, -1.0_dp], stat)
   end subroutine rows_append_pair

   subroutine grow(r, need, stat)
      type(rows_t), intent(inout) :: r
      integer, intent(in) :: need
      integer, intent(out) :: stat
      integer, allocatable :: ni(:)
      real(dp), allocatable :: nc(:)
      integer :: cap
      stat = 0
      if (need <= size(r%node)) return
      cap = max(need, 2*size(r%node))
      allocate (ni(cap), nc(cap), stat=stat)
      if (stat /= 0) return
      ni(1:size(r%node)) = r%node; nc(1:size(r%coef)) = r%coef
      call move_alloc(ni, r%node); call move_alloc(nc, r%coef)
   end subroutine grow

   !> Σ_k coef_k x(node_k) of row j (x indexed 0:n, 0 the ground).
   pure real(dp) function row_dot(r, j, x) result(d)
      type(rows_t), intent(in) :: r
      integer, intent(in) :: j
      real(dp), intent(in) :: x(0:)
      integer :: k
      d = 0.0_dp
      do k = r%first(j), r%first(j + 1) - 1
         d = d + r%coef(k)*x(r%node(k))
      end do
   end function row_dot

   !> Σ_k coef_k x(node_k) of row j for x indexed 1:n (no ground entry).
   pure real(dp) function row_dot1(r, j, x) result(d)
      type(rows_t), intent(in) :: r
      integer, intent(in) :: j
      real(dp), intent(in) :: x(:)
      integer :: k
      d = 0.0_dp
      do k = r%first(j), r%first(j + 1) - 1
         d = d + r%coef(k)*x(r%node(k))
      end do
   end function row_dot1

   !> y(node_k) += coef_k f over row j (the element's force on the nodes).
   pure subroutine row_add(r, j, f, y)
      type(rows_t), intent(in) :: r
      integer, intent(in) :: j
      real(dp), intent(in) :: f
      real(dp), intent(inout) :: y(0:)
      integer :: k
      do k = r%first(j), r%first(j + 1) - 1
         y(r%node(k)) = y(r%node(k)) + r%coef(k)*f
      end do
   end subroutine row_add

   !> A += val gᵀg over row j's terms, A in LAPACK band layout A(i, c) in ab(kr + i − c, c)
   !> (kr the row of the diagonal).
   pure subroutine row_stencil(ab, kr, r, j, val)
      real(dp), intent(inout) :: ab(:, :)
      integer, intent(in) :: kr, j
      type(rows_t), intent(in) :: r
      real(dp), intent(in) :: val
      integer :: p, q
      do q = r%first(j), r%first(j + 1) - 1
         do p = r%first(j), r%first(j + 1) - 1
            ab(kr + r%node(p) - r%node(q), r%node(q)) = ab(kr + r%node(p) - r%node(q), r%node(q)) &
               + val*r%coef(p)*r%coef(q)
         end do
      end do
   end subroutine row_stencil

   !> The first and one past the last term of row j.
   pure integer function row_lo(r, j)
      type(rows_t), intent(in) :: r
      integer, intent(in) :: j
      row_lo = r%first(j)
   end function row_lo

   pure integer function row_hi(r, j)
      type(rows_t), intent(in) :: r
      integer, intent(in) :: j
      row_hi = r%first(j + 1) - 1
   end function row_hi

   !> max − min of row j's nodes (0 for fewer than two terms): the band it needs.
   pure integer function row_span(r, j) result(s)
      type(rows_t), intent(in) :: r
      integer, intent(in) :: j
      s = 0
      if (r%first(j + 1) - r%first(j) < 2) return
      s = maxval(r%node(r%first(j):r%first(j + 1) - 1)) - minval(r%node(r%first(j):r%first(j + 1) - 1))
   end function row_span

   !> Whether row j is a node pair or a node against the ground: coefficients +1 and −1 (or
   !> one of them alone), the form of the chain and the fused methods.
   pure logical function row_is_pair(r, j) result(yes)
      type(rows_t), intent(in) :: r
      integer, intent(in) :: j
      integer :: lo, nt
      lo = r%first(j); nt = r%first(j + 1) - lo
      select case (nt)
      case (0)
         yes = .true.
      case (1)
         yes = abs(r%coef(lo)) == 1.0_dp
      case (2)
         yes = r%coef(lo)*r%coef(lo + 1) == -1.0_dp .and. abs(r%coef(lo)) == 1.0_dp
      case default
         yes = .false.
      end select
   end function row_is_pair

   !> A pair row's nodes: a the +1 side, b the −1 side (0: the ground).
   pure subroutine row_pair(r, j, a, b)
      type(rows_t), intent(in) :: r
      integer, intent(in) :: j
      integer, intent(out) :: a, b
      integer :: k
      a = 0; b = 0
      do k = r%first(j), r%first(j + 1) - 1
         if (r%coef(k) > 0.0_dp) then
            a = r%node(k)
         else
            b = r%node(k)
         end if
      end do
   end subroutine row_pair

   !> A pair row's +1 node (0: the ground): for the methods that take pairs only.
   pure integer function row_a(r, j) result(a)
      type(rows_t), intent(in) :: r
      integer, intent(in) :: j
      integer :: b
      call row_pair(r, j, a, b)
   end function row_a

   !> A pair row's −1 node (0: the ground).
   pure integer function row_b(r, j) result(b)
      type(rows_t), intent(in) :: r
      integer, intent(in) :: j
      integer :: a
      call row_pair(r, j, a, b)
   end function row_b

   !> The number of terms of all rows.
   pure integer function rows_terms(r)
      type(rows_t), intent(in) :: r
      rows_terms = r%first(r%n + 1) - 1
   end function rows_terms

   !> to ← from, the arrays moved.
   subroutine rows_move(from, to)
      type(rows_t), intent(inout) :: from, to
      to%n = from%n
      call move_alloc(from%first, to%first); call move_alloc(from%node, to%node)
      call move_alloc(from%coef, to%coef)
   end subroutine rows_move
end module martello_element_rows
