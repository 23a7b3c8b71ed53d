!> The observer's budget and the end of a run (docs/run-layer.md "The observer"): max_steps,
!> max_wall and the caller's progress callback after every accepted sample; the one
!> failure path (the message, t_reached, the open phases closed) and the finish.
submodule (martello_observer) budget
   use martello_integrator_settings, only: integrator_name
   use, intrinsic :: iso_c_binding, only: c_associated, c_f_procpointer
   implicit none

   !> Samples between looks at the clock (a system_clock call costs about a cheap step's
   !> arithmetic), and seconds between two progress reports.
   integer, parameter :: WATCH_EVERY = 32
   real(dp), parameter :: PROGRESS_INTERVAL = 0.25_dp

contains

   !> The budget and the caller, after every accepted sample: max_steps (every sample),
   !> and every WATCH_EVERY samples the clock: max_wall, and the progress callback at most
   !> every PROGRESS_INTERVAL seconds (a non-zero return stops the run). stat:
   !> MARTELLO_ERR_LIMIT or MARTELLO_ERR_INTERRUPTED with the message, else unchanged.
   module procedure observer_watch
      procedure(progress_callback), pointer :: report
      integer(i8) :: now
      real(dp) :: elapsed
      if (real(o%nsamples, dp) > o%max_steps) then
         write (o%message, '(a,a,es10.3,a,es12.5,a,es12.5,a)') integrator_name(o%kind), &
            ' took max_steps = ', o%max_steps, ' steps and reached t = ', t, ' s of t_end = ', &
            o%t_end, ' s: raise max_steps, or soften the scene (a stiffer contact or a lighter'// &
            ' mass needs more steps)'
         stat = MARTELLO_ERR_LIMIT
         call observer_finish(o, t); return
      end if
      if (mod(o%nsamples, int(WATCH_EVERY, i8)) /= 0) return
      if (o%max_wall <= 0.0_dp .and. .not. c_associated(o%progress)) return
      call system_clock(now)
      elapsed = real(now - o%clock0, dp)/real(o%clock_rate, dp)
      if (o%max_wall > 0.0_dp .and. elapsed > o%max_wall) then
         write (o%message, '(a,a,es10.3,a,i0,a,es12.5,a,es12.5,a)') integrator_name(o%kind), &
            ' ran for max_wall = ', o%max_wall, ' s (', o%nsamples, ' steps) and reached t = ', &
            t, ' s of t_end = ', o%t_end, ' s: raise max_wall, or coarsen the run'
         stat = MARTELLO_ERR_LIMIT
         call observer_finish(o, t); return
      end if
      if (.not. c_associated(o%progress)) return
      if (real(now - o%clock_last, dp) < PROGRESS_INTERVAL*real(o%clock_rate, dp)) return
      o%clock_last = now
      call c_f_procpointer(o%progress, report)
      if (report(o%progress_user, t, o%t_end, int(o%nsamples, c_long_long), elapsed) /= 0) then
         write (o%message, '(a,es12.5,a,i0,a)') 'interrupted at t = ', t, ' s (', o%nsamples, &
            ' steps)'
         stat = MARTELLO_ERR_INTERRUPTED
         call observer_finish(o, t)
      end if
   end procedure observer_watch

   !> A non-finite state, force or work at t (found here or by the method, e.g. in a
   !> right-hand side): the run has diverged.
   module procedure observer_fail_nonfinite
      write (o%message, '(a,a,es12.5,a)') integrator_name(o%kind), ' diverged at t = ', t, &
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
