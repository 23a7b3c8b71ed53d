!> The observer's budget and the end of a run (docs/run-layer.md "The observer"): max_steps,
!> max_wall and the caller's progress callback after every accepted sample; the one
!> failure path (the message, t_reached, the open phases closed) and the finish.
submodule (martello_observer) budget
   use martello_integrator_settings, only: integrator_name
   use, intrinsic :: iso_c_binding, only: c_associated, c_f_procpointer
   implicit none

   !> The most samples between looks at the clock (a system_clock call costs about a cheap
   !> step's arithmetic), the interval below which looks are spaced out (samples that take
   !> longer are watched one by one: an adaptive step of seconds reports, and stops on
   !> Ctrl-C, after each step), and seconds between two progress reports.
   integer, parameter :: WATCH_EVERY = 32
   real(dp), parameter :: WATCH_S = 1.0e-3_dp
   real(dp), parameter :: PROGRESS_INTERVAL = 0.25_dp

contains

   !> The budget and the caller, after every accepted sample: max_steps (every sample),
   !> and every watch_stride samples the clock (the stride doubles up to WATCH_EVERY while
   !> looks come within WATCH_S of each other, and halves down to 1 while they do not):
   !> max_wall, and the progress callback at most every PROGRESS_INTERVAL seconds (a
   !> non-zero return stops the run). stat:
   !> MARTELLO_ERR_LIMIT or MARTELLO_ERR_INTERRUPTED with the message, else unchanged.
   module procedure observer_watch
      procedure(progress_callback), pointer :: report
      integer(i8) :: now
      real(dp) :: elapsed
      if (real(o%nsamples, dp) > o%max_steps) then
         write (o%message, '(a,a,a,a,a,a,a,a)') integrator_name(o%kind), &
            ' took max_steps = ', sci(o%max_steps, 3), ' steps and reached t = ', sci(t, 5), &
            ' s of t_end = ', sci(o%t_end, 5), ' s: raise max_steps, or soften the scene (a stiffer contact or a lighter'// &
            ' mass needs more steps)'
         stat = MARTELLO_ERR_LIMIT
         call observer_finish(o, t); return
      end if
      o%watch_count = o%watch_count + 1
      if (o%watch_count < o%watch_stride) return
      o%watch_count = 0
      if (o%max_wall <= 0.0_dp .and. .not. c_associated(o%progress)) return
      call system_clock(now)
      if (real(now - o%clock_watched, dp) < WATCH_S*real(o%clock_rate, dp)) then
         o%watch_stride = min(2*o%watch_stride, int(WATCH_EVERY, i8))
      else
         o%watch_stride = max(o%watch_stride/2, 1_i8)
      end if
      o%clock_watched = now
      elapsed = real(now - o%clock0, dp)/real(o%clock_rate, dp)
      if (o%max_wall > 0.0_dp .and. elapsed > o%max_wall) then
         write (o%message, '(a,a,a,a,i0,a,a,a,a,a)') integrator_name(o%kind), &
            ' ran for max_wall = ', sci(o%max_wall, 3), ' s (', o%nsamples, ' steps) and reached t = ', &
            sci(t, 5), ' s of t_end = ', sci(o%t_end, 5), ' s: raise max_wall, or coarsen the run'
         stat = MARTELLO_ERR_LIMIT
         call observer_finish(o, t); return
      end if
      if (.not. c_associated(o%progress)) return
      if (real(now - o%clock_last, dp) < PROGRESS_INTERVAL*real(o%clock_rate, dp)) return
      o%clock_last = now
      call c_f_procpointer(o%progress, report)
      if (report(o%progress_user, t, o%t_end, int(o%nsamples, c_long_long), elapsed) /= 0) then
         write (o%message, '(a,a,a,i0,a)') 'interrupted at t = ', sci(t, 5), ' s (', o%nsamples, &
            ' steps)'
         stat = MARTELLO_ERR_INTERRUPTED
         call observer_finish(o, t)
      end if
   end procedure observer_watch

   !> A non-finite state, force or work at t (found here or by the method, e.g. in a
   !> right-hand side): the run has diverged.
   module procedure observer_fail_nonfinite
      write (o%message, '(a,a,a,a)') integrator_name(o%kind), ' diverged at t = ', sci(t, 5), &
         ' s: non-finite state (NaN/inf)'
      stat = MARTELLO_ERR_DIVERGED
      call observer_finish(o, t)
   end procedure observer_fail_nonfinite

   !> The method failed (code < 0) at t_reached, saying why. The results so far stay for
   !> diagnosis, open phases included (t_off = −1); they are not a result.
   module procedure observer_fail
      o%message = message
      stat = code
      call observer_finish(o, t_reached)
   end procedure observer_fail

   !> The run failed at t with code, o%message already saying why (memory running out): the
   !> observer's failure path, as every other failure takes it.
   module procedure observer_failed
      character(len=len(o%message)) :: msg
      integer :: failed
      msg = o%message; failed = code
      call observer_fail(o, failed, t, msg, code)
   end procedure observer_failed

   !> The run stops at t_reached (the end, or a failure): phases still open become events
   !> with t_off = −1.
   module procedure observer_finish
      integer :: c
      o%t_end_reached = t_reached
      do c = 1, size(o%ph_open)
         if (o%ph_open(c)) call observer_close_phase(o, c, -1.0_dp, 0.0_dp)
      end do
   end procedure observer_finish
end submodule budget
