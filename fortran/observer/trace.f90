!> The step trace (docs/results.md "Step trace"): one contact's force, the kinetic and
!> recoverable energies and the displacement of chosen nodes at every grid point of a
!> fixed-step run, whatever the history records (output.every), for the measures that need
!> them at every step (P4's pulse, energy and displacement field: docs/p4-bars.md). The samples are those of the history at every = 1, the same
!> numbers: the measures made on them do not depend on how the run is recorded.
submodule (martello_observer) trace
   use martello_run_quantities, only: E_KINETIC, E_RECOVERABLE
   implicit none

   !> The fix of the out-of-memory line of a trace
   character(len=*), parameter :: FIX_NO_TRACE = 'measure the run without its step trace (a shorter run)'

contains

   !> Append [t, f, kinetic, recoverable, u(trace_nodes)] (the energies evaluated at this
   !> sample: observer_energy_due), growing the trace by doubling.
   module procedure trace_append
      real(dp), allocatable :: tmp(:, :)
      integer :: st, nr
      character(len=96) :: what
      stat = MARTELLO_OK
      nr = 4
      if (allocated(o%trace_nodes)) nr = 4 + size(o%trace_nodes)
      if (.not. allocated(o%trace)) then
         allocate (o%trace(nr, int(min(o%n_grid + 1_i8, 1000000_i8))), stat=st)
         if (st /= 0) call grown(0)
         if (stat /= MARTELLO_OK) return
      end if
      if (o%ntrace == size(o%trace, 2)) then
         allocate (tmp(nr, 2*size(o%trace, 2)), stat=st)
         if (st /= 0) then
            call grown(2*size(o%trace, 2)); return
         end if
         tmp(:, 1:o%ntrace) = o%trace(:, 1:o%ntrace)
         call move_alloc(tmp, o%trace)
      end if
      o%ntrace = o%ntrace + 1
      o%trace(1:4, o%ntrace) = [t, f, o%energy(E_KINETIC), o%energy(E_RECOVERABLE)]
      if (nr > 4) o%trace(5:nr, o%ntrace) = u(o%trace_nodes)
   contains
      subroutine grown(rows)
         integer, intent(in) :: rows
         write (what, '(a,i0,a)') 'the step trace of a run grown to ', rows, ' steps'
         call out_of_memory(trim(what), REAL_BYTES*real(nr, dp)*rows, FIX_NO_TRACE, stat, o%message)
      end subroutine grown
   end procedure trace_append
end submodule trace
