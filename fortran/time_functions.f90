!> Scalar functions of time for nodal forces and ground acceleration. Analytic kinds are
!> evaluated exactly (no sampling), so order-of-accuracy tests are not polluted by
!> interpolation of the load; records are tables, linear between samples.
module martello_time_functions
   use martello_kinds, only: dp
   implicit none
   private
   public :: time_function_t, tf_value, tf_is_known, tf_next_breakpoint, tf_period, NPAR_TF, &
      TF_NONE, TF_CONSTANT, TF_TABLE, TF_SINE, TF_RECTANGULAR, TF_HALF_SINE

   integer, parameter :: TF_NONE = 0
   integer, parameter :: TF_CONSTANT = 1     !< par(1)
   integer, parameter :: TF_TABLE = 2        !< linear between (t_i, y_i), 0 outside [t_1, t_n], times par(1)
   integer, parameter :: TF_SINE = 3         !< par(1)·sin(par(2)·(t − par(4)) + par(3)) on [par(4), par(5)]
   integer, parameter :: TF_RECTANGULAR = 4  !< par(1) on [par(4), par(5)), 0 elsewhere
   integer, parameter :: TF_HALF_SINE = 5    !< par(1)·sin(π (t − par(4))/(par(5) − par(4))) on [par(4), par(5)]
   integer, parameter :: NPAR_TF = 5

   type :: time_function_t
      integer :: kind = TF_NONE
      real(dp) :: par(NPAR_TF) = 0.0_dp
      real(dp), allocatable :: t(:), y(:)
   end type time_function_t

contains

   pure logical function tf_is_known(kind)
      integer, intent(in) :: kind
      tf_is_known = kind >= TF_CONSTANT .and. kind <= TF_HALF_SINE
   end function tf_is_known

   !> Value at time t. The table search is a bisection: O(log n) per call, no saved cursor,
   !> so the function stays pure and thread-safe.
   pure function tf_value(tf, t) result(y)
      type(time_function_t), intent(in) :: tf
      real(dp), intent(in) :: t
      real(dp) :: y
      real(dp), parameter :: pi = acos(-1.0_dp)
      integer :: lo, hi, n
      real(dp) :: w

      y = 0.0_dp
      select case (tf%kind)
      case (TF_CONSTANT)
         y = tf%par(1)
      case (TF_SINE)
         if (t >= tf%par(4) .and. t <= tf%par(5)) &
            y = tf%par(1)*sin(tf%par(2)*(t - tf%par(4)) + tf%par(3))
      case (TF_RECTANGULAR)
         if (t >= tf%par(4) .and. t < tf%par(5)) y = tf%par(1)
      case (TF_HALF_SINE)
         if (t >= tf%par(4) .and. t <= tf%par(5)) &
            y = tf%par(1)*sin(pi*(t - tf%par(4))/(tf%par(5) - tf%par(4)))
      case (TF_TABLE)
         n = size(tf%t)
         if (n < 2) return
         if (t < tf%t(1) .or. t > tf%t(n)) return
         call bracket_sample(tf%t, t, lo, hi)
         w = (t - tf%t(lo))/(tf%t(hi) - tf%t(lo))
         y = tf%par(1)*((1.0_dp - w)*tf%y(lo) + w*tf%y(hi))
      end select
   end function tf_value

   !> The first time after t where the function is not smooth (docs/event-driven.md, time
   !> events): the start and end of a window, every sample of a table; huge() if none. An
   !> integrator that stops there never steps across a kink of the load.
   pure function tf_next_breakpoint(tf, t) result(tb)
      type(time_function_t), intent(in) :: tf
      real(dp), intent(in) :: t
      real(dp) :: tb
      integer :: lo, hi, n

      tb = huge(1.0_dp)
      select case (tf%kind)
      case (TF_SINE, TF_RECTANGULAR, TF_HALF_SINE)
         if (tf%par(4) > t) then
            tb = tf%par(4)
         else if (tf%par(5) > t) then
            tb = tf%par(5)
         end if
      case (TF_TABLE)
         n = size(tf%t)
         if (n < 1) return
         if (tf%t(n) <= t) return
         if (tf%t(1) > t) then
            tb = tf%t(1)
            return
         end if
         call bracket_sample(tf%t, t, lo, hi)
         tb = tf%t(hi)
      end select
   end function tf_next_breakpoint

   !> The period of the function's harmonic term (a sine 2π/ω, a half sine twice its window), or
   !> huge() for a function smooth between its breakpoints without one (a constant, a
   !> rectangular pulse, a table: linear between its samples, which are breakpoints). An
   !> integrator that holds a contact closed bounds its steps by it (docs/sundials-ode.md, held
   !> contacts).
   pure function tf_period(tf) result(p)
      type(time_function_t), intent(in) :: tf
      real(dp) :: p
      real(dp), parameter :: pi = acos(-1.0_dp)
      p = huge(1.0_dp)
      select case (tf%kind)
      case (TF_SINE)
         if (tf%par(2) /= 0.0_dp .and. tf%par(1) /= 0.0_dp .and. tf%par(5) > tf%par(4)) &
            p = 2.0_dp*pi/abs(tf%par(2))
      case (TF_HALF_SINE)
         if (tf%par(1) /= 0.0_dp .and. tf%par(5) > tf%par(4)) p = 2.0_dp*(tf%par(5) - tf%par(4))
      end select
   end function tf_period

   !> The samples around t by bisection, ts(lo) <= t < ts(hi) (hi = n at t = ts(n)), for
   !> ts(1) <= t <= ts(n): O(log n), no saved cursor (pure, thread-safe).
   pure subroutine bracket_sample(ts, t, lo, hi)
      real(dp), intent(in) :: ts(:), t
      integer, intent(out) :: lo, hi
      integer :: mid
      lo = 1; hi = size(ts)
      do while (hi - lo > 1)
         mid = (lo + hi)/2
         if (ts(mid) <= t) then
            lo = mid
         else
            hi = mid
         end if
      end do
   end subroutine bracket_sample
end module martello_time_functions
