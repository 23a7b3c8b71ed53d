!> The registry: every table that the C API, the C integrators and the Python front end share
!> is defined here once — integrators (kind, family, the settings each reads, the contact
!> schemes each runs), the settings (defaults and valid ranges), schemes, penalty laws, link
!> kinds, time functions, parameter slots, counters, energy terms, event fields, the history
!> layout, sizes and status codes — and read by name through martello_registry_*
!> (fortran/api_registry.f90, c/martello.h "registry"). tests/test_registry.py checks every
!> enum of c/martello.h and every copy in the Python binding against it.
!>
!> A table is a list of rows; each row has a name, a text and one number per column. Tables
!> whose "tables" row has a text name the prefix of their C constants: the row named
!> `hunt-crossley` of `laws` is MARTELLO_LAW_HUNT_CROSSLEY (upper case, '-' -> '_').
module martello_registry
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_positive_inf, ieee_negative_inf, &
      ieee_quiet_nan, ieee_is_nan
   use martello_kinds, only: dp
   use martello_status
   use martello_contact_laws, only: LAW_LINEAR, LAW_HERTZ, LAW_KELVIN, LAW_HUNT_CROSSLEY, &
      LAW_LANKARANI_NIKRAVESH, LAW_FLORES, LAW_GONTHIER, LAW_HERTZDAMP, LAW_JANKOWSKI, &
      NPAR_CONTACT, P_STIFF, P_EXPONENT, P_DAMPING, P_RESTITUTION, P_CLIP, law_exponent, &
      HERTZ_EXPONENT
   use martello_links, only: LINK_SPRING, LINK_DASHPOT, LINK_BILINEAR, LINK_FLUID_DAMPER, &
      LINK_BAR, NPAR_LINK, L_STIFF, L_DAMP, L_YIELD, L_HARDENING, L_ALPHA, L_VREG
   use martello_time_functions, only: TF_CONSTANT, TF_TABLE, TF_SINE, TF_RECTANGULAR, &
      TF_HALF_SINE, NPAR_TF
   use martello_run_quantities, only: NCOUNTERS, C_STEPS, C_REJECTED, C_NEWTON, C_RESIDUALS, &
      C_FACTORIZATIONS, C_EVENTS, C_JACOBIANS, C_ROOT_EVALS, C_CHATTER, C_FUSED, NENERGY, E_KINETIC, &
      E_RECOVERABLE, E_INPUT, E_DAMPING, E_PLASTIC, E_CONTACT, E_BALANCE, E_INITIAL, E_IMPACT, &
      NEVENT, EV_T_ON, EV_T_OFF, EV_V_IN, EV_V_OUT, EV_MAX_PEN, EV_MAX_FORCE, C_MODES
   implicit none
   private
   public :: SCHEME_PENALTY, SCHEME_LAGRANGE, SCHEME_AUGMENTED, SCHEME_RESTITUTION, &
      INT_NEWMARK, INT_HHT, INT_GENERALIZED_ALPHA, INT_CENTRAL_DIFFERENCE, INT_MOREAU_JEAN, &
      INT_NEWMARK_LAGRANGE, INT_RKF45, INT_RK8PD, INT_MSBDF, INT_IDA, INT_FAST_NONLINEAR, INT_CVODE, &
      INT_ARKODE, INT_LAST, NSETTINGS, S_DT, S_T_END, S_BETA, S_GAMMA, S_ALPHA, S_RHO_INF, S_TOL_RESIDUAL, &
      S_TOL_INCREMENT, S_MAX_NEWTON, S_CHECK_STABILITY, S_EVERY, S_DIVERGENCE_FACTOR, S_RTOL, &
      S_ATOL, S_THETA, S_EVENT_TOL, S_H_MAX, S_FUSED_CHAIN, S_MAX_STEPS, S_MAX_WALL, S_EVENT_SPLIT, S_METHOD, &
      S_MODAL_VECTORS, S_LOCAL_STEPPING, SETTINGS, &
      INTEGRATORS, METHODS, method_t, METHOD_DEFAULT, METHOD_BDF, METHOD_ADAMS, METHOD_ERK, &
      METHOD_DIRK, METHOD_IMEX, setting_t, integrator_t, &
      registry_shape, registry_column, registry_row, registry_find, registry_name, &
      NAME_LEN, TEXT_LEN, MAX_COLS, T_DOUBLE, T_INT, T_BOOL, TRACK_NODE_PEAKS, TRACK_LINK_PEAKS, &
      TRACK_CONTACT_PEAKS, TRACK_PHASES, TRACK_ALL

   integer, parameter :: NAME_LEN = 32, TEXT_LEN = 160

   ! What a run tracks (martello_run_set_tracking): bits of one number.
   integer, parameter :: TRACK_NODE_PEAKS = 1, TRACK_LINK_PEAKS = 2, TRACK_CONTACT_PEAKS = 4, &
                         TRACK_PHASES = 8, TRACK_ALL = 15

   ! Contact schemes (values frozen: the C API and scene files use them).
   integer, parameter :: SCHEME_PENALTY = 1, SCHEME_LAGRANGE = 2, SCHEME_AUGMENTED = 3, &
                         SCHEME_RESTITUTION = 4

   ! Integrator kinds (values frozen).
   integer, parameter :: INT_NEWMARK = 1, INT_HHT = 2, INT_GENERALIZED_ALPHA = 3, &
                         INT_CENTRAL_DIFFERENCE = 4, INT_MOREAU_JEAN = 5, &
                         INT_NEWMARK_LAGRANGE = 6, INT_RKF45 = 7, INT_RK8PD = 8, INT_MSBDF = 9, &
                         INT_IDA = 10, INT_FAST_NONLINEAR = 11, INT_CVODE = 12, INT_ARKODE = 13, &
                         INT_LAST = 13

   ! Integrator families: how the run is carried out (docs/integrators.md).
   integer, parameter :: FAMILY_NEWMARK = 1, FAMILY_TIME_STEPPING = 2, &
                         FAMILY_CONSTRAINED_NEWMARK = 3, FAMILY_EVENT_DRIVEN = 4, FAMILY_DAE = 5, &
                         FAMILY_MODAL = 6, FAMILY_ODE = 7

   ! The settings of a run, in the order of the fields of martello_settings after `kind`.
   integer, parameter :: S_DT = 1, S_T_END = 2, S_BETA = 3, S_GAMMA = 4, S_ALPHA = 5, &
                         S_RHO_INF = 6, S_TOL_RESIDUAL = 7, S_TOL_INCREMENT = 8, &
                         S_MAX_NEWTON = 9, S_CHECK_STABILITY = 10, S_EVERY = 11, &
                         S_DIVERGENCE_FACTOR = 12, S_RTOL = 13, S_ATOL = 14, S_THETA = 15, &
                         S_EVENT_TOL = 16, S_H_MAX = 17, S_FUSED_CHAIN = 18, &
                         S_MAX_STEPS = 19, S_MAX_WALL = 20, S_EVENT_SPLIT = 21, &
                         S_METHOD = 22, S_MODAL_VECTORS = 23, &
                         S_LOCAL_STEPPING = 24, NSETTINGS = 24
   integer, parameter :: MAX_COLS = NSETTINGS   !< the widest table: reads, a column per setting
   ! C types of the settings (rows of the table "setting_types")
   integer, parameter :: T_DOUBLE = 1, T_INT = 2, T_BOOL = 3
   ! how often a group of history columns repeats (rows of the table "history_per")
   integer, parameter :: PER_ONCE = 0, PER_NODE = 1, PER_CONTACT = 2, PER_LINK = 3, &
                         PER_ENERGY = 4

   real(dp), parameter :: BIG = huge(1.0_dp)   !< "no bound"; exported as ±infinity

   !> A named integer (most tables).
   type :: named_t
      character(len=NAME_LEN) :: name
      integer :: value
      character(len=TEXT_LEN) :: text
   end type named_t

   !> One setting: its C type, default and valid range (lo/hi, open or closed); text is the
   !> valid range in words, as error messages state it.
   type :: setting_t
      character(len=NAME_LEN) :: name
      integer :: type
      real(dp) :: default, lo, hi
      logical :: lo_open, hi_open
      character(len=TEXT_LEN) :: text
   end type setting_t

   !> One integrator: reads has bit S_x set for each setting it reads, schemes bit SCHEME_x
   !> for each contact scheme it can run (the compatibility table of docs/integrators.md).
   type :: integrator_t
      character(len=NAME_LEN) :: name
      integer :: kind, family
      logical :: adaptive
      integer :: reads, schemes
      character(len=TEXT_LEN) :: text
   end type integrator_t

   !> One method of the SUNDIALS ODE integrators (the setting method, docs/sundials-ode.md):
   !> its value, the integrator that runs it and its kind (METHOD_*). An ARKODE table's name is
   !> ARKODE's own without its prefix, lower case, '_' -> '-' (ARKODE_VERNER_8_5_6 is
   !> verner-8-5-6: stages, embedded order, order); an ImEx pair names the pair, whose
   !> ARKODE tables are <name>_ERK_<s_p_q> and <name>_DIRK_<s_p_q>. The implicit tables are
   !> those measured to their tolerance here (docs/sundials-ode.md, methods left out).
   type :: method_t
      character(len=NAME_LEN) :: name
      integer :: value, integrator, kind
      character(len=TEXT_LEN) :: text
   end type method_t

   type(named_t), parameter :: STATUS_CODES(*) = [ &
      named_t('MARTELLO_OK', MARTELLO_OK, 'success'), &
      named_t('MARTELLO_ILL_CONDITIONED', MARTELLO_ILL_CONDITIONED, &
              'solved, but digits were lost: read the message'), &
      named_t('MARTELLO_ROOT_FOUND', MARTELLO_ROOT_FOUND, 'an event stopped the integration'), &
      named_t('MARTELLO_ERR_ARGUMENT', MARTELLO_ERR_ARGUMENT, 'a bad argument: the message names it'), &
      named_t('MARTELLO_ERR_MEMORY', MARTELLO_ERR_MEMORY, 'out of memory'), &
      named_t('MARTELLO_ERR_SINGULAR', MARTELLO_ERR_SINGULAR, 'singular system (a node held by nothing)'), &
      named_t('MARTELLO_ERR_NOT_CONVERGED', MARTELLO_ERR_NOT_CONVERGED, &
              'Newton, active set or Uzawa did not converge'), &
      named_t('MARTELLO_ERR_DIVERGED', MARTELLO_ERR_DIVERGED, 'NaN or energy growth beyond the input'), &
      named_t('MARTELLO_ERR_UNSUPPORTED', MARTELLO_ERR_UNSUPPORTED, &
              'scheme, integrator or link not possible here'), &
      named_t('MARTELLO_ERR_UNSTABLE', MARTELLO_ERR_UNSTABLE, 'explicit step beyond its stability limit'), &
      named_t('MARTELLO_ERR_LAPACK', MARTELLO_ERR_LAPACK, &
              'LAPACK reported an illegal argument (a bug in martello)'), &
      named_t('MARTELLO_ERR_STEP_UNDERFLOW', MARTELLO_ERR_STEP_UNDERFLOW, &
              'the step size fell below what the time resolves'), &
      named_t('MARTELLO_ERR_EXTERNAL', MARTELLO_ERR_EXTERNAL, 'GSL or SUNDIALS reported a failure'), &
      named_t('MARTELLO_ERR_STATE', MARTELLO_ERR_STATE, 'call out of order'), &
      named_t('MARTELLO_ERR_LIMIT', MARTELLO_ERR_LIMIT, 'max_steps or max_wall reached before t_end'), &
      named_t('MARTELLO_ERR_INTERRUPTED', MARTELLO_ERR_INTERRUPTED, &
              'stopped by the caller (its progress callback asked to)')]

   type(named_t), parameter :: SCHEMES(*) = [ &
      named_t('penalty', SCHEME_PENALTY, 'a force law on the penetration'), &
      named_t('lagrange', SCHEME_LAGRANGE, 'non-penetration constraint; its multiplier is the force'), &
      named_t('augmented-lagrange', SCHEME_AUGMENTED, 'augmented Lagrangian (Uzawa), static analyses only'), &
      named_t('restitution', SCHEME_RESTITUTION, 'instantaneous impacts with Newton''s restitution e')]

   type(named_t), parameter :: LAWS(*) = [ &
      named_t('linear', LAW_LINEAR, 'F = k delta'), &
      named_t('hertz', LAW_HERTZ, 'Hertz (1882): F = K delta^n'), &
      named_t('kelvin', LAW_KELVIN, 'Anagnostopoulos (1988): F = k delta + c ddelta'), &
      named_t('hunt-crossley', LAW_HUNT_CROSSLEY, 'Hunt & Crossley (1975): F = K delta^n (1 + chi ddelta)'), &
      named_t('lankarani-nikravesh', LAW_LANKARANI_NIKRAVESH, 'Lankarani & Nikravesh (1990), HC form'), &
      named_t('flores', LAW_FLORES, 'Flores et al. (2011), HC form'), &
      named_t('gonthier', LAW_GONTHIER, 'Gonthier et al. (2004), HC form'), &
      named_t('hertzdamp', LAW_HERTZDAMP, 'Muthukumar & DesRoches (2006): HC form, n = 3/2'), &
      named_t('jankowski', LAW_JANKOWSKI, 'Jankowski (2005): nonlinear viscoelastic, n = 3/2')]

   type(named_t), parameter :: LINKS(*) = [ &
      named_t('spring', LINK_SPRING, 'linear spring f = k du'), &
      named_t('dashpot', LINK_DASHPOT, 'linear dashpot f = c dv'), &
      named_t('bilinear', LINK_BILINEAR, 'bilinear hysteretic spring with kinematic hardening'), &
      named_t('fluid_damper', LINK_FLUID_DAMPER, 'fluid-viscous damper f = c |dv|^alpha sign(dv)'), &
      named_t('bar', LINK_BAR, 'axial bar element, k = EA/L')]

   type(named_t), parameter :: TIME_FUNCTIONS(*) = [ &
      named_t('constant', TF_CONSTANT, 'par[0]'), &
      named_t('table', TF_TABLE, 'linear between samples (t_i, y_i) times par[0], 0 outside'), &
      named_t('sine', TF_SINE, 'par[0] sin(par[1] (t - par[3]) + par[2]) on [par[3], par[4]]'), &
      named_t('rectangular', TF_RECTANGULAR, 'par[0] on [par[3], par[4]), 0 elsewhere'), &
      named_t('half_sine', TF_HALF_SINE, 'par[0] sin(pi (t - par[3])/(par[4] - par[3])) on [par[3], par[4]]')]

   ! Parameter slots, 0-based as in C.
   type(named_t), parameter :: CONTACT_PARAMETERS(*) = [ &
      named_t('stiff', P_STIFF - 1, 'k (linear, kelvin), K (hertz type), beta (jankowski)'), &
      named_t('exponent', P_EXPONENT - 1, 'n, read by hertz and the Hunt-Crossley family'), &
      named_t('damping', P_DAMPING - 1, 'kelvin: c [N s/m]; HC family: a = chi v_in; jankowski: xi'), &
      named_t('restitution', P_RESTITUTION - 1, 'target e the damping is derived from, or -1'), &
      named_t('clip', P_CLIP - 1, 'kelvin: 1 clips the force at 0 (no tension)')]

   type(named_t), parameter :: LINK_PARAMETERS(*) = [ &
      named_t('stiff', L_STIFF - 1, 'k [N/m]; a bar stores EA/L'), &
      named_t('damp', L_DAMP - 1, 'c: [N s/m] dashpot, [N (s/m)^alpha] fluid damper'), &
      named_t('yield', L_YIELD - 1, 'bilinear: yield force F_y > 0'), &
      named_t('hardening', L_HARDENING - 1, 'bilinear: post-yield stiffness ratio in [0, 1)'), &
      named_t('alpha', L_ALPHA - 1, 'fluid damper exponent in (0, 2]'), &
      named_t('vreg', L_VREG - 1, 'fluid damper regularisation speed >= 0')]

   ! Indices (0-based) of martello_run_counters, martello_run_energy and martello_run_events.
   type(named_t), parameter :: COUNTERS(*) = [ &
      named_t('steps', C_STEPS - 1, 'accepted steps'), &
      named_t('rejected_steps', C_REJECTED - 1, 'rejected steps (adaptive)'), &
      named_t('newton_iterations', C_NEWTON - 1, 'Newton iterations'), &
      named_t('residual_evaluations', C_RESIDUALS - 1, 'residual or right-hand side evaluations'), &
      named_t('factorizations', C_FACTORIZATIONS - 1, 'matrix factorizations'), &
      named_t('events', C_EVENTS - 1, 'contact events (onsets, impacts, releases)'), &
      named_t('jacobian_evaluations', C_JACOBIANS - 1, 'Jacobian evaluations'), &
      named_t('root_evaluations', C_ROOT_EVALS - 1, 'root-function evaluations'), &
      named_t('contact_chatter_resolutions', C_CHATTER - 1, &
              'steps where a contact was held open (docs/integrators.md)'), &
      named_t('modes', C_MODES - 1, 'modes of the linear part (fast-nonlinear)'), &
      named_t('fused_chain_steps', C_FUSED - 1, 'steps taken by the fused chain step (docs/run-layer.md)')]

   type(named_t), parameter :: ENERGY_TERMS(*) = [ &
      named_t('kinetic', E_KINETIC - 1, 'kinetic energy [J]'), &
      named_t('recoverable', E_RECOVERABLE - 1, 'elastic energy of links and contacts [J]'), &
      named_t('input', E_INPUT - 1, 'work of the external forces [J]'), &
      named_t('damping', E_DAMPING - 1, 'dissipated by dashpots and dampers [J]'), &
      named_t('plastic', E_PLASTIC - 1, 'dissipated by yielding links [J]'), &
      named_t('contact', E_CONTACT - 1, 'dissipated by penalty contact damping [J]'), &
      named_t('balance', E_BALANCE - 1, 'initial + input - kinetic - recoverable - dissipated [J]'), &
      named_t('initial', E_INITIAL - 1, 'mechanical energy at t = 0 [J]'), &
      named_t('impact', E_IMPACT - 1, 'lost in impacts (restitution, Lagrange) [J]')]

   type(named_t), parameter :: TRACKING(*) = [ &
      named_t('node_peaks', TRACK_NODE_PEAKS, 'every node''s peaks (martello_run_peaks,'// &
              ' martello_run_abs_peaks)'), &
      named_t('link_peaks', TRACK_LINK_PEAKS, 'every link''s largest force and elongation'// &
              ' (martello_run_link_peaks)'), &
      named_t('contact_peaks', TRACK_CONTACT_PEAKS, 'every contact''s max penetration and force'), &
      named_t('phases', TRACK_PHASES, 'the contact phases (martello_run_events,'// &
              ' martello_run_set_phase_lists)'), &
      named_t('all', TRACK_ALL, 'all of them (the default)')]

   type(named_t), parameter :: EVENT_FIELDS(*) = [ &
      named_t('t_on', EV_T_ON - 1, 'onset of the contact phase [s]'), &
      named_t('t_off', EV_T_OFF - 1, 'separation [s] (-1: still closed at the end)'), &
      named_t('v_in', EV_V_IN - 1, 'approach speed [m/s]'), &
      named_t('v_out', EV_V_OUT - 1, 'separation speed [m/s]'), &
      named_t('max_penetration', EV_MAX_PEN - 1, 'largest penetration of the phase [m]'), &
      named_t('max_force', EV_MAX_FORCE - 1, 'largest force of the phase [N]')]

   type(named_t), parameter :: CONSTANTS(*) = [ &
      named_t('GROUND', -1, 'node number of the ground (a rigid wall)'), &
      named_t('NPAR_CONTACT', NPAR_CONTACT, 'contact parameter slots; unused ones must be 0'), &
      named_t('NPAR_LINK', NPAR_LINK, 'link parameter slots'), &
      named_t('NPAR_TF', NPAR_TF, 'time-function parameter slots'), &
      named_t('NCOUNTERS', NCOUNTERS, 'cost counters of a run'), &
      named_t('NENERGY', NENERGY, 'energy terms of a run'), &
      named_t('NEVENT', NEVENT, 'values per contact phase')]

   type(named_t), parameter :: FAMILIES(*) = [ &
      named_t('newmark', FAMILY_NEWMARK, 'fixed-step Newmark family with Newton (docs/integrators.md)'), &
      named_t('time-stepping', FAMILY_TIME_STEPPING, 'impulse-level time stepping (docs/moreau-jean.md)'), &
      named_t('constrained-newmark', FAMILY_CONSTRAINED_NEWMARK, &
              'Newmark with Lagrange multipliers and impact steps (docs/moreau-jean.md)'), &
      named_t('event-driven', FAMILY_EVENT_DRIVEN, &
              'GSL adaptive ODE steppers with event location (docs/event-driven.md)'), &
      named_t('dae', FAMILY_DAE, 'SUNDIALS IDA on the contact DAE with events (docs/ida.md)'), &
      named_t('modal', FAMILY_MODAL, &
              'modes of the linear part, nonlinear elements as pseudo-forces (docs/integrators.md)'), &
      named_t('ode', FAMILY_ODE, &
              'SUNDIALS CVODE and ARKODE on the first-order ODE with root finding (docs/sundials-ode.md)')]

   type(named_t), parameter :: SETTING_TYPES(*) = [named_t('double', T_DOUBLE, 'C double'), &
      named_t('int', T_INT, 'C int'), named_t('bool', T_BOOL, 'C bool (stdbool.h)')]

   !> The history of martello_run_history: each record is these groups in this order.
   type(named_t), parameter :: HISTORY(*) = [ &
      named_t('t', PER_ONCE, 'time [s]'), named_t('u', PER_NODE, 'displacement of each output node'), &
      named_t('v', PER_NODE, 'velocity of each output node'), &
      named_t('a', PER_NODE, 'acceleration of each output node'), &
      named_t('penetration', PER_CONTACT, 'penetration of each output contact'), &
      named_t('force', PER_CONTACT, 'force of each output contact'), &
      named_t('link_force', PER_LINK, 'force of each output link (NaN where not reported)'), &
      named_t('elongation', PER_LINK, 'elongation of each output link (NaN where not reported)'), &
      named_t('energy', PER_ENERGY, 'the energy terms, in the order of the table energy')]

   type(named_t), parameter :: HISTORY_PER(*) = [named_t('once', PER_ONCE, 'one column'), &
      named_t('node', PER_NODE, 'one column per output node'), &
      named_t('contact', PER_CONTACT, 'one column per output contact'), &
      named_t('link', PER_LINK, 'one column per output link'), &
      named_t('energy_term', PER_ENERGY, 'one column per energy term')]

   type(setting_t), parameter :: SETTINGS(NSETTINGS) = [ &
      setting_t('dt', T_DOUBLE, 0.0_dp, 0.0_dp, BIG, .true., .false., 'a number > 0'), &
      setting_t('t_end', T_DOUBLE, 0.0_dp, 0.0_dp, BIG, .true., .false., 'a number > 0'), &
      setting_t('beta', T_DOUBLE, 0.25_dp, 0.0_dp, BIG, .true., .false., &
                'a number > 0 (beta = 0 is central-difference)'), &
      setting_t('gamma', T_DOUBLE, 0.5_dp, 0.5_dp, BIG, .false., .false., 'a number >= 0.5'), &
      setting_t('alpha', T_DOUBLE, 0.0_dp, -1.0_dp/3.0_dp, 0.0_dp, .false., .false., &
                'a number in [-1/3, 0]'), &
      setting_t('rho_inf', T_DOUBLE, 1.0_dp, 0.0_dp, 1.0_dp, .false., .false., 'a number in [0, 1]'), &
      setting_t('tol_residual', T_DOUBLE, 1.0e-9_dp, 0.0_dp, BIG, .true., .false., 'a number > 0'), &
      setting_t('tol_increment', T_DOUBLE, 1.0e-11_dp, 0.0_dp, BIG, .true., .false., 'a number > 0'), &
      setting_t('max_newton', T_INT, 30.0_dp, 0.0_dp, BIG, .true., .false., 'a number > 0'), &
      setting_t('check_stability', T_BOOL, 1.0_dp, 0.0_dp, 1.0_dp, .false., .false., 'true or false'), &
      setting_t('every', T_INT, 1.0_dp, 0.0_dp, BIG, .true., .false., 'a number > 0'), &
      setting_t('divergence_factor', T_DOUBLE, 10.0_dp, 1.0_dp, BIG, .true., .false., 'a number > 1'), &
      setting_t('rtol', T_DOUBLE, 1.0e-8_dp, 0.0_dp, BIG, .true., .false., 'a number > 0'), &
      setting_t('atol', T_DOUBLE, 1.0e-12_dp, 0.0_dp, BIG, .true., .false., 'a number > 0'), &
      setting_t('theta', T_DOUBLE, 0.5_dp, 0.5_dp, 1.0_dp, .false., .false., 'a number in [0.5, 1]'), &
      setting_t('event_tol', T_DOUBLE, 1.0e-12_dp, 0.0_dp, BIG, .true., .false., 'a number > 0'), &
      setting_t('h_max', T_DOUBLE, 0.0_dp, 0.0_dp, BIG, .false., .false., 'a number >= 0'), &
      setting_t('fused_chain', T_BOOL, 1.0_dp, 0.0_dp, 1.0_dp, .false., .false., 'true or false'), &
      setting_t('max_steps', T_DOUBLE, 1.0e8_dp, 1.0_dp, 2.0_dp**53, .false., .false., &
                'a whole number in [1, 2^53]'), &
      setting_t('max_wall', T_DOUBLE, 0.0_dp, 0.0_dp, BIG, .false., .false., &
                'a number >= 0 [s] (0: no limit)'), &
      setting_t('event_split', T_BOOL, 0.0_dp, 0.0_dp, 1.0_dp, .false., .false., 'true or false'), &
      setting_t('method', T_INT, 0.0_dp, 0.0_dp, 399.0_dp, .false., .false., &
                'a row of the table methods for the integrator, or 0 (its default)'), &
      setting_t('modal_vectors', T_INT, 0.0_dp, 0.0_dp, BIG, .false., .false., &
                'a whole number >= 0 (0: all modes; m: m load-dependent Ritz vectors)'), &
      setting_t('local_stepping', T_BOOL, 0.0_dp, 0.0_dp, 1.0_dp, .false., .false., 'true or false')]

   ! Methods (values frozen; table "methods"): the kinds
   integer, parameter :: METHOD_DEFAULT = 0, METHOD_BDF = 1, METHOD_ADAMS = 2, METHOD_ERK = 3, &
                         METHOD_DIRK = 4, METHOD_IMEX = 5
   type(method_t), parameter :: METHODS(*) = [ &
      method_t('bdf', 1, INT_CVODE, METHOD_BDF, 'CVODE variable-order BDF, orders 1-5 (the default)'), &
      method_t('adams', 2, INT_CVODE, METHOD_ADAMS, 'CVODE variable-order Adams-Moulton, orders 1-12'), &
      method_t('heun-euler-2-1-2', 100, INT_ARKODE, METHOD_ERK, 'explicit RK, order 2'), &
      method_t('bogacki-shampine-4-2-3', 101, INT_ARKODE, METHOD_ERK, 'explicit RK, order 3'), &
      method_t('zonneveld-5-3-4', 103, INT_ARKODE, METHOD_ERK, 'explicit RK, order 4'), &
      method_t('cash-karp-6-4-5', 106, INT_ARKODE, METHOD_ERK, 'explicit RK, order 5'), &
      method_t('fehlberg-6-4-5', 107, INT_ARKODE, METHOD_ERK, 'explicit RK, order 5'), &
      method_t('dormand-prince-7-4-5', 108, INT_ARKODE, METHOD_ERK, &
               'explicit RK, order 5 (the arkode default)'), &
      method_t('verner-8-5-6', 110, INT_ARKODE, METHOD_ERK, 'explicit RK, order 6'), &
      method_t('fehlberg-13-7-8', 111, INT_ARKODE, METHOD_ERK, 'explicit RK, order 8'), &
      method_t('sdirk-2-1-2', 200, INT_ARKODE, METHOD_DIRK, 'diagonally implicit RK, order 2'), &
      method_t('trbdf2-3-3-2', 202, INT_ARKODE, METHOD_DIRK, 'TR-BDF2 as an ESDIRK, order 2'), &
      method_t('kvaerno-4-2-3', 203, INT_ARKODE, METHOD_DIRK, 'ESDIRK, order 3'), &
      method_t('sdirk-5-3-4', 207, INT_ARKODE, METHOD_DIRK, 'SDIRK, order 4'), &
      method_t('kvaerno-5-3-4', 208, INT_ARKODE, METHOD_DIRK, 'ESDIRK, order 4'), &
      method_t('kvaerno-7-4-5', 210, INT_ARKODE, METHOD_DIRK, 'ESDIRK, order 5'), &
      method_t('ark324l2sa-4-2-3', 300, INT_ARKODE, METHOD_IMEX, 'ImEx additive RK, order 3'), &
      method_t('ark436l2sa-6-3-4', 301, INT_ARKODE, METHOD_IMEX, 'ImEx additive RK, order 4'), &
      method_t('ark437l2sa-7-3-4', 302, INT_ARKODE, METHOD_IMEX, 'ImEx additive RK, order 4'), &
      method_t('ark548l2sa-8-4-5', 303, INT_ARKODE, METHOD_IMEX, &
               'ImEx additive RK, order 5: loads explicit, internal forces implicit'), &
      method_t('ark548l2sab-8-4-5', 304, INT_ARKODE, METHOD_IMEX, 'ImEx additive RK, order 5')]

   ! Settings read by groups of integrators (bit S_x).
   integer, parameter :: READS_BASE = 2**S_DT + 2**S_T_END + 2**S_EVERY + 2**S_MAX_STEPS + 2**S_MAX_WALL
   integer, parameter :: READS_DIVERGENCE = 2**S_DIVERGENCE_FACTOR
   integer, parameter :: READS_NEWTON = 2**S_TOL_RESIDUAL + 2**S_TOL_INCREMENT + 2**S_MAX_NEWTON
   integer, parameter :: READS_ADAPTIVE = 2**S_RTOL + 2**S_ATOL + 2**S_EVENT_TOL + 2**S_H_MAX
   ! Penalty contacts are smooth forces (every integrator but Newmark–Lagrange, built for rigid
   ! impacts); Lagrange and restitution contacts need event location or impulse-level time
   ! stepping; augmented Lagrange is a static scheme.
   integer, parameter :: RUNS_PENALTY = 2**SCHEME_PENALTY
   integer, parameter :: RUNS_RIGID = 2**SCHEME_LAGRANGE + 2**SCHEME_RESTITUTION

   type(integrator_t), parameter :: INTEGRATORS(INT_LAST) = [ &
      integrator_t('newmark', INT_NEWMARK, FAMILY_NEWMARK, .false., &
                   READS_BASE + READS_DIVERGENCE + READS_NEWTON + 2**S_BETA + 2**S_GAMMA + &
                   2**S_CHECK_STABILITY + 2**S_FUSED_CHAIN + 2**S_EVENT_SPLIT, &
                   RUNS_PENALTY, 'Newmark (1959) beta-gamma, implicit'), &
      integrator_t('hht', INT_HHT, FAMILY_NEWMARK, .false., &
                   READS_BASE + READS_DIVERGENCE + READS_NEWTON + 2**S_ALPHA + 2**S_EVENT_SPLIT, &
                   RUNS_PENALTY, &
                   'Hilber, Hughes & Taylor (1977) alpha method'), &
      integrator_t('generalized-alpha', INT_GENERALIZED_ALPHA, FAMILY_NEWMARK, .false., &
                   READS_BASE + READS_DIVERGENCE + READS_NEWTON + 2**S_RHO_INF + 2**S_EVENT_SPLIT, &
                   RUNS_PENALTY, &
                   'Chung & Hulbert (1993) generalized-alpha'), &
      integrator_t('central-difference', INT_CENTRAL_DIFFERENCE, FAMILY_NEWMARK, .false., &
                   READS_BASE + READS_DIVERGENCE + 2**S_CHECK_STABILITY, RUNS_PENALTY, &
                   'explicit central difference (Newmark beta = 0, lumped mass)'), &
      integrator_t('moreau-jean', INT_MOREAU_JEAN, FAMILY_TIME_STEPPING, .false., &
                   READS_BASE + READS_DIVERGENCE + 2**S_THETA, RUNS_PENALTY + RUNS_RIGID, &
                   'Moreau (1988), Jean (1999) theta time stepping with impulses'), &
      integrator_t('newmark-lagrange', INT_NEWMARK_LAGRANGE, FAMILY_CONSTRAINED_NEWMARK, .false., &
                   READS_BASE + READS_DIVERGENCE + READS_NEWTON, RUNS_RIGID, &
                   'Papadrakakis et al. (1991) Newmark with Lagrange multipliers'), &
      integrator_t('rkf45', INT_RKF45, FAMILY_EVENT_DRIVEN, .true., READS_BASE + READS_ADAPTIVE, &
                   RUNS_PENALTY + RUNS_RIGID, 'Runge-Kutta-Fehlberg 4(5), GSL'), &
      integrator_t('rk8pd', INT_RK8PD, FAMILY_EVENT_DRIVEN, .true., READS_BASE + READS_ADAPTIVE, &
                   RUNS_PENALTY + RUNS_RIGID, 'Prince-Dormand 8(9), GSL'), &
      integrator_t('msbdf', INT_MSBDF, FAMILY_EVENT_DRIVEN, .true., READS_BASE + READS_ADAPTIVE, &
                   RUNS_PENALTY + RUNS_RIGID, 'multistep BDF (stiff), GSL'), &
      integrator_t('ida', INT_IDA, FAMILY_DAE, .true., &
                   READS_BASE + READS_DIVERGENCE + READS_ADAPTIVE + 2**S_LOCAL_STEPPING, RUNS_PENALTY + RUNS_RIGID, &
                   'SUNDIALS IDA, variable-order BDF on the contact DAE'), &
      integrator_t('fast-nonlinear', INT_FAST_NONLINEAR, FAMILY_MODAL, .false., &
                   READS_BASE + READS_DIVERGENCE + 2**S_TOL_RESIDUAL + 2**S_MAX_NEWTON + 2**S_MODAL_VECTORS, &
                   RUNS_PENALTY, 'Wilson (2002) fast nonlinear analysis: exact modal steps, pseudo-forces'), &
      integrator_t('cvode', INT_CVODE, FAMILY_ODE, .true., &
                   READS_BASE + READS_DIVERGENCE + READS_ADAPTIVE + 2**S_METHOD + 2**S_LOCAL_STEPPING, &
                   RUNS_PENALTY + RUNS_RIGID, &
                   'SUNDIALS CVODE, variable-order BDF or Adams, banded analytic Jacobian'), &
      integrator_t('arkode', INT_ARKODE, FAMILY_ODE, .true., &
                   READS_BASE + READS_DIVERGENCE + READS_ADAPTIVE + 2**S_METHOD + 2**S_LOCAL_STEPPING, &
                   RUNS_PENALTY + RUNS_RIGID, &
                   'SUNDIALS ARKODE, explicit, diagonally implicit or ImEx Runge-Kutta tables')]

   !> The tables; text: the prefix of their C constants in c/martello.h ('' if none).
   type(named_t), parameter :: TABLES(*) = [ &
      named_t('tables', 0, ''), named_t('status', 0, ''), named_t('integrators', 0, 'MARTELLO_INT_'), &
      named_t('families', 0, 'MARTELLO_FAMILY_'), named_t('settings', 0, ''), &
      named_t('setting_types', 0, ''), named_t('reads', 0, ''), named_t('compatibility', 0, ''), &
      named_t('schemes', 0, 'MARTELLO_SCHEME_'), named_t('laws', 0, 'MARTELLO_LAW_'), &
      named_t('links', 0, 'MARTELLO_LINK_'), named_t('time_functions', 0, 'MARTELLO_TF_'), &
      named_t('contact_parameters', 0, 'MARTELLO_P_'), named_t('link_parameters', 0, 'MARTELLO_L_'), &
      named_t('counters', 0, 'MARTELLO_COUNTER_'), named_t('energy', 0, 'MARTELLO_ENERGY_'), &
      named_t('events', 0, 'MARTELLO_EVENT_'), named_t('constants', 0, 'MARTELLO_'), &
      named_t('history', 0, ''), named_t('history_per', 0, ''), &
      named_t('tracking', 0, 'MARTELLO_TRACK_'), named_t('methods', 0, '')]

contains

   !> Rows and columns of a table; ok = .false. if there is no such table.
   pure subroutine registry_shape(table, rows, cols, ok)
      character(len=*), intent(in) :: table
      integer, intent(out) :: rows, cols
      logical, intent(out) :: ok
      ok = .true.
      cols = 1
      select case (table)
      case ('tables'); rows = size(TABLES); cols = 2
      case ('status'); rows = size(STATUS_CODES)
      case ('integrators'); rows = size(INTEGRATORS); cols = 3
      case ('families'); rows = size(FAMILIES)
      case ('settings'); rows = size(SETTINGS); cols = 6
      case ('setting_types'); rows = size(SETTING_TYPES)
      case ('reads'); rows = size(INTEGRATORS); cols = size(SETTINGS)
      case ('compatibility'); rows = size(INTEGRATORS); cols = size(SCHEMES)
      case ('schemes'); rows = size(SCHEMES)
      case ('laws'); rows = size(LAWS); cols = 3
      case ('links'); rows = size(LINKS)
      case ('time_functions'); rows = size(TIME_FUNCTIONS)
      case ('contact_parameters'); rows = size(CONTACT_PARAMETERS)
      case ('link_parameters'); rows = size(LINK_PARAMETERS)
      case ('counters'); rows = size(COUNTERS)
      case ('energy'); rows = size(ENERGY_TERMS)
      case ('events'); rows = size(EVENT_FIELDS)
      case ('tracking'); rows = size(TRACKING)
      case ('constants'); rows = size(CONSTANTS)
      case ('history'); rows = size(HISTORY)
      case ('history_per'); rows = size(HISTORY_PER)
      case ('methods'); rows = size(METHODS); cols = 3
      case default
         rows = 0; cols = 0; ok = .false.
      end select
   end subroutine registry_shape

   !> The name of column j (1-based) of a table.
   pure subroutine registry_column(table, j, name, ok)
      character(len=*), intent(in) :: table
      integer, intent(in) :: j
      character(len=NAME_LEN), intent(out) :: name
      logical, intent(out) :: ok
      integer :: rows, cols
      character(len=NAME_LEN), parameter :: SETTING_COLS(6) = [character(len=NAME_LEN) :: &
         'default', 'min', 'max', 'min_open', 'max_open', 'type'], &
         INTEGRATOR_COLS(3) = [character(len=NAME_LEN) :: 'value', 'family', 'adaptive'], &
         LAW_COLS(3) = [character(len=NAME_LEN) :: 'value', 'exponent', 'exponent_fixed'], &
         METHOD_COLS(3) = [character(len=NAME_LEN) :: 'value', 'integrator', 'kind']
      name = ''
      call registry_shape(table, rows, cols, ok)
      ok = ok .and. j >= 1 .and. j <= cols
      if (.not. ok) return
      select case (table)
      case ('tables'); name = merge('rows', 'cols', j == 1)
      case ('integrators'); name = INTEGRATOR_COLS(j)
      case ('settings'); name = SETTING_COLS(j)
      case ('reads'); name = SETTINGS(j)%name
      case ('compatibility'); name = SCHEMES(j)%name
      case ('laws'); name = LAW_COLS(j)
      case ('methods'); name = METHOD_COLS(j)
      case ('history'); name = 'per'
      case default; name = 'value'
      end select
   end subroutine registry_column

   !> Row i (1-based) of a table: its name, its numbers (values(1:cols)) and its text.
   pure subroutine registry_row(table, i, name, values, text, ok)
      character(len=*), intent(in) :: table
      integer, intent(in) :: i
      character(len=NAME_LEN), intent(out) :: name
      real(dp), intent(out) :: values(:)
      character(len=TEXT_LEN), intent(out) :: text
      logical, intent(out) :: ok
      integer :: rows, cols, j
      real(dp) :: par(NPAR_CONTACT), n
      type(named_t), allocatable :: t(:)
      name = ''; text = ''; values = 0.0_dp
      call registry_shape(table, rows, cols, ok)
      ok = ok .and. i >= 1 .and. i <= rows .and. size(values) >= cols
      if (.not. ok) return
      select case (table)
      case ('tables')
         call registry_shape(TABLES(i)%name, rows, cols, ok)
         name = TABLES(i)%name; text = TABLES(i)%text
         values(1:2) = [real(dp) :: rows, cols]
      case ('integrators', 'reads', 'compatibility')
         name = INTEGRATORS(i)%name; text = INTEGRATORS(i)%text
         if (table == 'integrators') then
            values(1:3) = [real(dp) :: INTEGRATORS(i)%kind, INTEGRATORS(i)%family, &
                           merge(1, 0, INTEGRATORS(i)%adaptive)]
         else if (table == 'reads') then
            values(1:cols) = [(merge(1.0_dp, 0.0_dp, btest(INTEGRATORS(i)%reads, j)), j = 1, cols)]
         else
            values(1:cols) = [(merge(1.0_dp, 0.0_dp, btest(INTEGRATORS(i)%schemes, SCHEMES(j)%value)), &
                               j = 1, cols)]
         end if
      case ('methods')
         name = METHODS(i)%name; text = METHODS(i)%text
         values(1:3) = [real(dp) :: METHODS(i)%value, METHODS(i)%integrator, METHODS(i)%kind]
      case ('settings')
         name = SETTINGS(i)%name; text = SETTINGS(i)%text
         values(1:6) = [SETTINGS(i)%default, unbounded(SETTINGS(i)%lo, -1), &
                        unbounded(SETTINGS(i)%hi, 1), merge(1.0_dp, 0.0_dp, SETTINGS(i)%lo_open), &
                        merge(1.0_dp, 0.0_dp, SETTINGS(i)%hi_open), real(SETTINGS(i)%type, dp)]
      case ('laws')
         ! the exponent the law uses: fixed by the law, or read from P_EXPONENT (default Hertz)
         par = 0.0_dp
         par(P_EXPONENT) = ieee_value(1.0_dp, ieee_quiet_nan)
         n = law_exponent(LAWS(i)%value, par)
         name = LAWS(i)%name; text = LAWS(i)%text
         values(1:3) = [real(LAWS(i)%value, dp), merge(HERTZ_EXPONENT, n, ieee_is_nan(n)), &
                        merge(0.0_dp, 1.0_dp, ieee_is_nan(n))]
      case default
         t = named_table(table)
         ok = i <= size(t)
         if (ok) then
            name = t(i)%name; values(1) = t(i)%value; text = t(i)%text
         end if
      end select
   end subroutine registry_row

   !> The 1-based row of a table named name; 0 if none.
   pure integer function registry_find(table, name) result(i)
      character(len=*), intent(in) :: table, name
      integer :: rows, cols
      logical :: ok
      character(len=NAME_LEN) :: rname
      character(len=TEXT_LEN) :: text
      real(dp) :: values(MAX_COLS)
      call registry_shape(table, rows, cols, ok)
      do i = 1, rows
         call registry_row(table, i, rname, values, text, ok)
         if (rname == name) return
      end do
      i = 0
   end function registry_find

   !> The name of the row of a table whose (first) value is value; 'unknown' if none.
   pure function registry_name(table, value) result(name)
      character(len=*), intent(in) :: table
      integer, intent(in) :: value
      character(len=:), allocatable :: name
      integer :: rows, cols, i
      logical :: ok
      character(len=NAME_LEN) :: rname
      character(len=TEXT_LEN) :: text
      real(dp) :: values(MAX_COLS)
      call registry_shape(table, rows, cols, ok)
      name = 'unknown'
      do i = 1, rows
         call registry_row(table, i, rname, values, text, ok)
         if (nint(values(1)) == value) then
            name = trim(rname); return
         end if
      end do
   end function registry_name

   ! ---------------------------------------------------------------- private helpers

   pure function named_table(table) result(t)
      character(len=*), intent(in) :: table
      type(named_t), allocatable :: t(:)
      select case (table)
      case ('status'); t = STATUS_CODES
      case ('families'); t = FAMILIES
      case ('setting_types'); t = SETTING_TYPES
      case ('schemes'); t = SCHEMES
      case ('links'); t = LINKS
      case ('time_functions'); t = TIME_FUNCTIONS
      case ('contact_parameters'); t = CONTACT_PARAMETERS
      case ('link_parameters'); t = LINK_PARAMETERS
      case ('counters'); t = COUNTERS
      case ('energy'); t = ENERGY_TERMS
      case ('events'); t = EVENT_FIELDS
      case ('tracking'); t = TRACKING
      case ('constants'); t = CONSTANTS
      case ('history'); t = HISTORY
      case ('history_per'); t = HISTORY_PER
      case default; allocate (t(0))
      end select
   end function named_table

   !> A bound of a range as exported: ±infinity for "none".
   pure real(dp) function unbounded(x, sgn)
      real(dp), intent(in) :: x
      integer, intent(in) :: sgn
      unbounded = x
      if (abs(x) >= BIG) unbounded = merge(ieee_value(1.0_dp, ieee_positive_inf), &
                                           ieee_value(1.0_dp, ieee_negative_inf), sgn > 0)
   end function unbounded
end module martello_registry
