!> The indices of what a dynamic run measures, shared by the observer that fills them and the
!> registry that names them (docs/results.md): cost counters, energy terms, and the values of
!> one contact phase. Parameters only, so that both can use it without a module cycle.
module martello_run_quantities
   implicit none
   private
   public :: NCOUNTERS, C_STEPS, C_REJECTED, C_NEWTON, C_RESIDUALS, C_FACTORIZATIONS, C_EVENTS, &
      C_JACOBIANS, C_ROOT_EVALS, C_CHATTER, C_MODES, C_FUSED, NENERGY, E_KINETIC, E_RECOVERABLE, E_INPUT, E_DAMPING, &
      E_PLASTIC, E_CONTACT, E_BALANCE, E_INITIAL, E_IMPACT, NEVENT, EV_T_ON, EV_T_OFF, &
      EV_V_IN, EV_V_OUT, EV_MAX_PEN, EV_MAX_FORCE, PEAK_V, PEAK_A, PEAK_PEN, PEAK_FORCE, &
      PEAK_LINK_FORCE, PEAK_LINK_DU

   ! cost counters
   integer, parameter :: NCOUNTERS = 11
   integer, parameter :: C_STEPS = 1, C_REJECTED = 2, C_NEWTON = 3, C_RESIDUALS = 4, &
                         C_FACTORIZATIONS = 5, C_EVENTS = 6, C_JACOBIANS = 7, C_ROOT_EVALS = 8, &
                         C_CHATTER = 9, C_MODES = 10, C_FUSED = 11
   ! energy terms [J]: balance = initial + input − kinetic − recoverable − dissipated (≈ 0)
   integer, parameter :: NENERGY = 9
   integer, parameter :: E_KINETIC = 1, E_RECOVERABLE = 2, E_INPUT = 3, E_DAMPING = 4, &
                         E_PLASTIC = 5, E_CONTACT = 6, E_BALANCE = 7, E_INITIAL = 8, E_IMPACT = 9
   ! one contact phase
   integer, parameter :: NEVENT = 6
   integer, parameter :: EV_T_ON = 1, EV_T_OFF = 2, EV_V_IN = 3, EV_V_OUT = 4, &
                         EV_MAX_PEN = 5, EV_MAX_FORCE = 6
   ! the peaks a method may locate inside its steps (observer_peak; c/martello_internal.h
   ! MARTELLO_PEAK_*): node |v| and |a|, contact δ and force, link |force| and |elongation|
   integer, parameter :: PEAK_V = 1, PEAK_A = 2, PEAK_PEN = 3, PEAK_FORCE = 4, &
                         PEAK_LINK_FORCE = 5, PEAK_LINK_DU = 6
end module martello_run_quantities
