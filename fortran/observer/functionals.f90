!> Linear functionals q = R·u of the state tracked by the observer (docs/results.md, "Frames
!> and buildings"): a frame's or building's member end forces, drifts, storey forces and plan
!> points are such rows of the state, so their peaks are taken like a node's — at every
!> accepted sample whatever the history records, and inside each stretch between two
!> samples where the rate q̇ = R·v changes sign: on a fixed step at the extremum of the cubic
!> Hermite of (q, q̇) (O(h⁴) in q, as a node's), on an adaptive method's step, whose ends
!> fall where its error control puts them, on the quintic Hermite of (q, q̇, q̈) (O(h⁶):
!> below the method's own error, so the peak moves with the steps no more than the state
!> does; docs/results.md). The resultant √(q_a² + q_b²) of a pair of rows likewise: at every
!> sample, and inside each stretch where the rate of its square, q_a q̇_a + q_b q̇_b, turns
!> from rising to falling, at the maximum of the two rows' interpolants (the same Hermites).
submodule (martello_observer) functionals
   implicit none

contains

   !> The results' arrays of the rows and pairs f holds: extremes at ∓huge, times −1.
   module procedure functionals_start
      integer :: n, np
      n = f%n; np = 0
      if (allocated(f%pair)) np = size(f%pair, 2)
      if (allocated(f%q_max)) deallocate (f%q_max, f%q_min, f%t_max, f%t_min, f%q0, f%r0, f%a0, &
                                          f%q1, f%r1, f%a1, f%res_max, f%t_res)
      allocate (f%q_max(n), f%q_min(n), f%t_max(n), f%t_min(n), f%q0(n), f%r0(n), f%a0(n), &
                f%q1(n), f%r1(n), f%a1(n), f%res_max(np), f%t_res(np), stat=stat)
      if (stat /= 0) return
      f%q_max = -huge(1.0_dp); f%q_min = huge(1.0_dp); f%t_max = -1.0_dp; f%t_min = -1.0_dp
      f%res_max = -1.0_dp; f%t_res = -1.0_dp; f%q0 = 0.0_dp; f%r0 = 0.0_dp; f%a0 = 0.0_dp
      f%q1 = 0.0_dp; f%r1 = 0.0_dp; f%a1 = 0.0_dp
      f%t0 = -1.0_dp
   end procedure functionals_start

   !> Each row at the sample (q, q̇ at t), its extremum inside the stretch from the last
   !> sample (at t0) where q̇ changes sign, then the pairs' resultants at the sample. The
   !> first of equal values keeps its time (as the samples in order would).
   module procedure functionals_track
      integer :: f_, k, p
      real(dp) :: q, r, acc, h, s(2), pk(2), x
      if (f%n == 0) return
      h = t - f%t0
      do f_ = 1, f%n
         q = 0.0_dp; r = 0.0_dp; acc = 0.0_dp
         do k = f%ptr(f_), f%ptr(f_ + 1) - 1
            q = q + f%val(k)*u(f%col(k))
            r = r + f%val(k)*v(f%col(k))
            acc = acc + f%val(k)*a(f%col(k))
         end do
         if (f%t0 >= 0.0_dp .and. h > 0.0_dp .and. f%r0(f_)*r < 0.0_dp) then
            if (fixed_steps) then
               call cubic_hermite_extrema(h, f%q0(f_), f%r0(f_), q, r, s, pk)
               do k = 1, 2
                  if (.not. (s(k) > 0.0_dp .and. s(k) < 1.0_dp)) cycle
                  call raise(f_, f%t0 + s(k)*h, pk(k))
               end do
            else
               call quintic_extremum(h, f%q0(f_), f%r0(f_), f%a0(f_), q, r, acc, s(1), pk(1))
               call located(f_, f%t0 + s(1)*h, pk(1), f%q0(f_), q, f%r0(f_) > 0.0_dp)
            end if
         end if
         call raise(f_, t, q)
         f%q1(f_) = q; f%r1(f_) = r; f%a1(f_) = acc
      end do
      if (allocated(f%pair)) then
         do p = 1, size(f%pair, 2)
            call resultant(p)
         end do
      end if
      f%q0 = f%q1; f%r0 = f%r1; f%a0 = f%a1
      f%t0 = t
   contains
      !> Pair p's resultant: its maximum inside the stretch where the rate of its square turns
      !> from rising to falling (located as the rows' extrema are: on a fixed step over the
      !> located value alone, on an adaptive one at the located time over the stretch's ends
      !> too), then its value at the sample.
      subroutine resultant(p)
         integer, intent(in) :: p
         integer :: i, j
         real(dp) :: w, y, sx, r0sq, r1sq
         i = f%pair(1, p); j = f%pair(2, p)
         r0sq = f%q0(i)*f%r0(i) + f%q0(j)*f%r0(j)
         r1sq = f%q1(i)*f%r1(i) + f%q1(j)*f%r1(j)
         if (f%t0 >= 0.0_dp .and. h > 0.0_dp .and. r0sq > 0.0_dp .and. r1sq < 0.0_dp) then
            call resultant_maximum(h, [f%q0(i), f%r0(i), f%a0(i), f%q1(i), f%r1(i), f%a1(i)], &
                                   [f%q0(j), f%r0(j), f%a0(j), f%q1(j), f%r1(j), f%a1(j)], &
                                   fixed_steps, sx, y)
            if (fixed_steps) then
               if (y > f%res_max(p)) then
                  f%res_max(p) = y; f%t_res(p) = f%t0 + sx*h
               end if
            else
               w = max(y, hypot(f%q0(i), f%q0(j)), hypot(f%q1(i), f%q1(j)))
               if (w >= f%res_max(p)) then
                  f%res_max(p) = w; f%t_res(p) = f%t0 + sx*h
               end if
            end if
         end if
         x = hypot(f%q1(i), f%q1(j))
         if (x > f%res_max(p)) then
            f%res_max(p) = x; f%t_res(p) = t
         end if
      end subroutine resultant
      subroutine raise(i, tq, y)
         integer, intent(in) :: i
         real(dp), intent(in) :: tq, y
         if (y > f%q_max(i)) then
            f%q_max(i) = y; f%t_max(i) = tq
         end if
         if (y < f%q_min(i)) then
            f%q_min(i) = y; f%t_min(i) = tq
         end if
      end subroutine raise
      !> The extremum of a stretch whose rate changes sign (a maximum if rising) located at
      !> tq with value y: the stretch's extremum is inside it, so it takes the located time
      !> even where an end's sample (q0, q1) is above the interpolant's value by the
      !> interpolant's error — else the time would be that of a step's end near the
      !> extremum, which moves with the steps (a time is known to √(error/|q̈|) there).
      subroutine located(i, tq, y, q0, q1, rising)
         integer, intent(in) :: i
         real(dp), intent(in) :: tq, y, q0, q1
         logical, intent(in) :: rising
         real(dp) :: w
         if (rising) then
            w = max(y, q0, q1)
            if (w >= f%q_max(i)) then
               f%q_max(i) = w; f%t_max(i) = tq
            end if
         else
            w = min(y, q0, q1)
            if (w <= f%q_min(i)) then
               f%q_min(i) = w; f%t_min(i) = tq
            end if
         end if
      end subroutine located
   end procedure functionals_track

   !> The maximum of √(q_a² + q_b²) inside a step of h where the rate of its square,
   !> q_a q̇_a + q_b q̇_b, falls from positive to negative: each row on its Hermite over the
   !> step (ea, eb = q0, q̇0, q̈0, q1, q̇1, q̈1 of each; cubic of (q, q̇) on fixed steps, quintic
   !> with q̈ on adaptive ones, as the rows' own extrema), the rate bisected. Its abscissa s in
   !> (0, 1) and value p.
   pure subroutine resultant_maximum(h, ea, eb, fixed_steps, s, p)
      real(dp), intent(in) :: h, ea(6), eb(6)
      logical, intent(in) :: fixed_steps
      real(dp), intent(out) :: s, p
      real(dp) :: ca(0:5), cb(0:5), qa, da, qb, db
      call hermite_coefficients(h, ea, fixed_steps, ca)
      call hermite_coefficients(h, eb, fixed_steps, cb)
      s = rate_root(ca, .true., cb)
      call hermite_at(ca, s, qa, da)
      call hermite_at(cb, s, qb, db)
      p = hypot(qa, qb)
   end subroutine resultant_maximum

   !> The power coefficients in x = (t − t0)/h of a row's Hermite over a step (e = q0, q̇0,
   !> q̈0, q1, q̇1, q̈1): the cubic of (q, q̇) on fixed steps, the quintic of (q, q̇, q̈) else.
   pure subroutine hermite_coefficients(h, e, fixed_steps, c)
      real(dp), intent(in) :: h, e(6)
      logical, intent(in) :: fixed_steps
      real(dp), intent(out) :: c(0:5)
      real(dp) :: dq, d0, d1, e0, e1
      dq = e(4) - e(1); d0 = h*e(2); d1 = h*e(5); e0 = h*h*e(3); e1 = h*h*e(6)
      c = 0.0_dp
      c(0) = e(1); c(1) = d0
      if (fixed_steps) then
         c(2) = 3.0_dp*dq - 2.0_dp*d0 - d1
         c(3) = -2.0_dp*dq + d0 + d1
      else
         c(2) = 0.5_dp*e0
         c(3) = 10.0_dp*dq - 6.0_dp*d0 - 4.0_dp*d1 - 1.5_dp*e0 + 0.5_dp*e1
         c(4) = -15.0_dp*dq + 8.0_dp*d0 + 7.0_dp*d1 + 1.5_dp*e0 - e1
         c(5) = 6.0_dp*dq - 3.0_dp*(d0 + d1) - 0.5_dp*(e0 - e1)
      end if
   end subroutine hermite_coefficients

   !> The value and x-derivative of a polynomial of power coefficients c at x.
   pure subroutine hermite_at(c, x, q, d)
      real(dp), intent(in) :: c(0:5), x
      real(dp), intent(out) :: q, d
      q = c(0) + x*(c(1) + x*(c(2) + x*(c(3) + x*(c(4) + x*c(5)))))
      d = c(1) + x*(2.0_dp*c(2) + x*(3.0_dp*c(3) + x*(4.0_dp*c(4) + x*5.0_dp*c(5))))
   end subroutine hermite_at

   !> The extremum inside a step of h where the rate changes sign (r0·r1 < 0) on the quintic
   !> Hermite of (q, q̇, q̈) at both ends (hermite_coefficients): its abscissa s in (0, 1)
   !> (rate_root) and value p.
   pure subroutine quintic_extremum(h, q0, r0, a0, q1, r1, a1, s, p)
      real(dp), intent(in) :: h, q0, r0, a0, q1, r1, a1
      real(dp), intent(out) :: s, p
      real(dp) :: c(0:5), d
      call hermite_coefficients(h, [q0, r0, a0, q1, r1, a1], .false., c)
      s = rate_root(c, r0 > 0.0_dp)
      call hermite_at(c, s, p, d)
   end subroutine quintic_extremum

   !> The root in (0, 1) of a rate that changes sign over a step, bisected 60 times (to the
   !> last bit of x): the rate of the polynomial of power coefficients c (hermite_at), or, with
   !> cb, that of half the square of the resultant of the two, q q' + q_b q_b'; rising: the
   !> rate is positive at x = 0 (and negative at 1).
   pure real(dp) function rate_root(c, rising, cb) result(s)
      real(dp), intent(in) :: c(0:5)
      logical, intent(in) :: rising
      real(dp), intent(in), optional :: cb(0:5)
      real(dp) :: lo, hi, x, q, d, qb, db, rate
      integer :: it
      lo = 0.0_dp; hi = 1.0_dp
      do it = 1, 60
         x = 0.5_dp*(lo + hi)
         call hermite_at(c, x, q, d)
         rate = d
         if (present(cb)) then
            call hermite_at(cb, x, qb, db)
            rate = q*d + qb*db
         end if
         if ((rate > 0.0_dp) .eqv. rising) then
            lo = x
         else
            hi = x
         end if
      end do
      s = 0.5_dp*(lo + hi)
   end function rate_root
end submodule functionals
