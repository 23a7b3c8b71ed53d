!> The domain of every parameter a link kind, a contact scheme and law, and a time function
!> read (docs/c-api.md, "Parameter domains"): the C API checks them when an item is added
!> (martello_model_add_link(s), _add_contact(s), _add_chain, _add_nodal_force,
!> _set_ground_acceleration), so a caller that is not the Python front end (whose loader
!> checks the same domains, naming the scene's fields) gets MARTELLO_ERR_ARGUMENT and a
!> message naming the slot, instead of a run that fails later (a Hertz contact whose
!> exponent a zero-initialised block left 0 ended its run with MARTELLO_ERR_EXTERNAL).
!> Slots a kind or law does not read are not checked beyond being finite (the model's doors
!> check that); the contact slots past P_CLIP are reserved and must be 0 (model.f90).
module martello_parameter_domains
   use martello_kinds, only: dp
   use martello_status, only: sci
   use martello_links, only: LINK_SPRING, LINK_DASHPOT, LINK_BILINEAR, LINK_FLUID_DAMPER, LINK_BAR, &
      NPAR_LINK, L_STIFF, L_DAMP, L_YIELD, L_HARDENING, L_ALPHA, L_VREG
   use martello_contact_laws, only: NPAR_CONTACT, P_STIFF, P_EXPONENT, P_DAMPING, P_RESTITUTION, &
      P_CLIP, LAW_KELVIN, LAW_HERTZ, LAW_HUNT_CROSSLEY, LAW_LANKARANI_NIKRAVESH, LAW_FLORES, &
      LAW_GONTHIER
   use martello_time_functions, only: NPAR_TF, TF_SINE, TF_RECTANGULAR, TF_HALF_SINE
   use martello_registry, only: PENALTY => SCHEME_PENALTY, AUGMENTED => SCHEME_AUGMENTED, &
      RESTITUTION => SCHEME_RESTITUTION
   implicit none
   private
   public :: link_domain_problem, contact_domain_problem, function_domain_problem

   integer, parameter :: OPEN = 1, CLOSED = 0
   real(dp), parameter :: NONE = huge(1.0_dp)

contains

   !> '' if the parameters a link of this kind reads lie in their domains, else what is wrong
   !> (its kind, the slot's C name, the value and the domain).
   pure function link_domain_problem(kind, par) result(msg)
      integer, intent(in) :: kind
      real(dp), intent(in) :: par(NPAR_LINK)
      character(len=:), allocatable :: msg
      msg = ''
      select case (kind)
      case (LINK_SPRING)
         call need(msg, 'spring', 'MARTELLO_L_STIFF', 'k', par(L_STIFF), 0.0_dp, NONE, OPEN, OPEN)
      case (LINK_DASHPOT)
         call need(msg, 'dashpot', 'MARTELLO_L_DAMP', 'c', par(L_DAMP), 0.0_dp, NONE, OPEN, OPEN)
      case (LINK_BILINEAR)
         call need(msg, 'bilinear', 'MARTELLO_L_STIFF', 'k', par(L_STIFF), 0.0_dp, NONE, OPEN, OPEN)
         call need(msg, 'bilinear', 'MARTELLO_L_YIELD', 'F_y', par(L_YIELD), 0.0_dp, NONE, OPEN, OPEN)
         call need(msg, 'bilinear', 'MARTELLO_L_HARDENING', 'hardening', par(L_HARDENING), &
                   0.0_dp, 1.0_dp, CLOSED, OPEN)
      case (LINK_FLUID_DAMPER)
         call need(msg, 'fluid_damper', 'MARTELLO_L_DAMP', 'c', par(L_DAMP), 0.0_dp, NONE, OPEN, OPEN)
         call need(msg, 'fluid_damper', 'MARTELLO_L_ALPHA', 'alpha', par(L_ALPHA), 0.0_dp, 2.0_dp, &
                   OPEN, CLOSED)
         call need(msg, 'fluid_damper', 'MARTELLO_L_VREG', 'v_reg', par(L_VREG), 0.0_dp, NONE, &
                   CLOSED, OPEN)
      case (LINK_BAR)
         call need(msg, 'bar', 'MARTELLO_L_STIFF', 'EA/L', par(L_STIFF), 0.0_dp, NONE, OPEN, OPEN)
      end select
   end function link_domain_problem

   !> '' if the parameters a contact of this scheme (and, for penalty, law) reads lie in their
   !> domains, else what is wrong. The restitution slot is −1 (none) or in [0, 1] for every
   !> scheme, and must be given (in [0, 1]) for a restitution contact.
   pure function contact_domain_problem(scheme, law, par) result(msg)
      integer, intent(in) :: scheme, law
      real(dp), intent(in) :: par(NPAR_CONTACT)
      character(len=:), allocatable :: msg
      msg = ''
      if (par(P_RESTITUTION) /= -1.0_dp .or. scheme == RESTITUTION) &
         call need(msg, 'contact', 'MARTELLO_P_RESTITUTION', 'e (-1: none)', par(P_RESTITUTION), &
                   0.0_dp, 1.0_dp, CLOSED, CLOSED)
      select case (scheme)
      case (PENALTY)
         call need(msg, 'penalty', 'MARTELLO_P_STIFF', 'stiffness', par(P_STIFF), 0.0_dp, NONE, &
                   OPEN, OPEN)
         select case (law)     ! the laws whose exponent is the caller's (law_exponent)
         case (LAW_HERTZ, LAW_HUNT_CROSSLEY, LAW_LANKARANI_NIKRAVESH, LAW_FLORES, LAW_GONTHIER)
            call need(msg, 'penalty', 'MARTELLO_P_EXPONENT', 'n (1.5: Hertz)', par(P_EXPONENT), &
                      0.0_dp, NONE, OPEN, OPEN)
         end select
         call need(msg, 'penalty', 'MARTELLO_P_DAMPING', 'damping', par(P_DAMPING), 0.0_dp, NONE, &
                   CLOSED, OPEN)
         if (len(msg) == 0 .and. par(P_CLIP) /= 0.0_dp .and. &
             .not. (par(P_CLIP) == 1.0_dp .and. law == LAW_KELVIN)) &
            msg = 'penalty: par[MARTELLO_P_CLIP] = '//num(par(P_CLIP))//' must be 0, or 1 for'// &
                  ' the kelvin law (clip its force at 0)'
      case (AUGMENTED)
         call need(msg, 'augmented-lagrange', 'MARTELLO_P_STIFF', 'stiffness', par(P_STIFF), &
                   0.0_dp, NONE, OPEN, OPEN)
      end select
   end function contact_domain_problem

   !> '' if a time function's window and frequency are valid (its kind is known), else what
   !> is wrong: a window [t_start, t_end] that is not later at its end (a half sine over a
   !> zero window divides by zero) and, for a sine, omega > 0.
   pure function function_domain_problem(kind, par) result(msg)
      integer, intent(in) :: kind
      real(dp), intent(in) :: par(NPAR_TF)
      character(len=:), allocatable :: msg
      msg = ''
      select case (kind)
      case (TF_SINE, TF_RECTANGULAR, TF_HALF_SINE)
         if (.not. par(5) > par(4)) msg = 'par[4] = t_end = '//num(par(5))// &
            ' must be later than par[3] = t_start = '//num(par(4))
         if (kind == TF_SINE) call need(msg, 'sine', '1', 'omega', par(2), 0.0_dp, NONE, OPEN, OPEN)
      end select
   end function function_domain_problem

   !> msg ← "what: par[slot] (name) = value must be <domain>" unless lo < value < hi (each end
   !> closed or open); an earlier problem in msg is kept.
   pure subroutine need(msg, what, slot, name, value, lo, hi, lo_open, hi_open)
      character(len=:), allocatable, intent(inout) :: msg
      character(len=*), intent(in) :: what, slot, name
      real(dp), intent(in) :: value, lo, hi
      integer, intent(in) :: lo_open, hi_open
      logical :: ok
      if (len(msg) > 0) return
      ok = value > lo .or. (lo_open == CLOSED .and. value == lo)
      ok = ok .and. (value < hi .or. (hi_open == CLOSED .and. value == hi))
      if (ok) return
      msg = what//': par['//slot//'] ('//name//') = '//num(value)//' must be '//domain(lo, hi, &
            lo_open, hi_open)
   end subroutine need

   !> A domain in words: "> 0", ">= 0", "in [0, 1)".
   pure function domain(lo, hi, lo_open, hi_open) result(text)
      real(dp), intent(in) :: lo, hi
      integer, intent(in) :: lo_open, hi_open
      character(len=:), allocatable :: text
      if (hi >= NONE) then
         text = trim(merge('> ', '>=', lo_open == OPEN))//' '//short(lo)
      else
         text = 'in '//merge('(', '[', lo_open == OPEN)//short(lo)//', '//short(hi)// &
                merge(')', ']', hi_open == OPEN)
      end if
   end function domain

   !> A value as a message gives it (its exponent always with its E: martello_status sci).
   pure function num(x) result(text)
      real(dp), intent(in) :: x
      character(len=:), allocatable :: text
      text = sci(x, 5)
   end function num

   !> A bound of a domain: 0, 1, 2 as written.
   pure function short(x) result(text)
      real(dp), intent(in) :: x
      character(len=:), allocatable :: text
      character(len=32) :: buf
      write (buf, '(g0)') x
      text = trim(adjustl(buf))
      if (index(text, '.') > 0) then
         do while (text(len(text):len(text)) == '0')
            text = text(:len(text) - 1)
         end do
         if (text(len(text):len(text)) == '.') text = text(:len(text) - 1)
      end if
   end function short
end module martello_parameter_domains
