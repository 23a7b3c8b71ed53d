!> Penalty contact laws for one contact pair: force, tangents, elastic energy and the
!> published damping-from-restitution formulas (docs/problems.md P5).
!>
!> Conventions (shared with the C and Python layers):
!>   delta  = (u_a - u_b) - gap, penetration; contact when delta > 0,
!>   ddelta = d(delta)/dt,
!>   f      > 0 in compression; f = 0 and both tangents 0 whenever delta <= 0.
!> Invalid input (unknown law, e out of range, v_in <= 0 with HC damping) gives a quiet NaN
!> rather than a silently wrong number: pure procedures cannot stop in Fortran 2008.
module martello_contact_laws
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
   use, intrinsic :: iso_fortran_env, only: int8
   use martello_kinds, only: dp
   implicit none
   private

   public :: LAW_LINEAR, LAW_HERTZ, LAW_KELVIN, LAW_HUNT_CROSSLEY, LAW_LANKARANI_NIKRAVESH, &
             LAW_FLORES, LAW_GONTHIER, LAW_HERTZDAMP, LAW_JANKOWSKI
   public :: NPAR_CONTACT, P_STIFF, P_EXPONENT, P_DAMPING, P_RESTITUTION, P_CLIP, HERTZ_EXPONENT
   public :: contact_force, contact_elastic_energy, damping_from_restitution, exact_hc_factor
   public :: law_is_known, law_exponent, law_rate_bounded
   public :: BRANCH_OFF, BRANCH_ON, BRANCH_CLIPPED, AFFINE_LINEAR, AFFINE_KELVIN, &
             AFFINE_KELVIN_CLIPPED

   ! Law identifiers: values are frozen, the C and Python layers use the same integers.
   integer, parameter :: LAW_LINEAR = 1
   integer, parameter :: LAW_HERTZ = 2
   integer, parameter :: LAW_KELVIN = 3
   integer, parameter :: LAW_HUNT_CROSSLEY = 4
   integer, parameter :: LAW_LANKARANI_NIKRAVESH = 5
   integer, parameter :: LAW_FLORES = 6
   integer, parameter :: LAW_GONTHIER = 7
   integer, parameter :: LAW_HERTZDAMP = 8
   integer, parameter :: LAW_JANKOWSKI = 9

   !> The laws that are affine on each branch (linear, k δ; Kelvin, k δ + c δ̇, clipped at 0
   !> or not) and their branches, as a method that holds them per contact keeps them in bytes
   !> (the fused chain step, and observer_block that measures it): open, pushing, and in
   !> phase with no force (a clipped Kelvin law past its cut-off).
   integer(int8), parameter :: AFFINE_LINEAR = 1, AFFINE_KELVIN = 2, AFFINE_KELVIN_CLIPPED = 3
   integer(int8), parameter :: BRANCH_OFF = 0, BRANCH_ON = 1, BRANCH_CLIPPED = 2

   ! Layout of par(NPAR_CONTACT); slots 6 to 8 are reserved and must be zero. The effective
   ! mass m* the kelvin and jankowski laws need is the model's (martello_effective_mass).
   integer, parameter :: NPAR_CONTACT = 8
   integer, parameter :: P_STIFF = 1       ! k (linear, kelvin), K (hertz type), beta (Jankowski)
   integer, parameter :: P_EXPONENT = 2    ! n, read only by hertz and the HC family (see below)
   integer, parameter :: P_DAMPING = 3     ! kelvin: c [N s/m]; HC family: a = chi*v_in [-]; Jankowski: xi [-]
   integer, parameter :: P_RESTITUTION = 4 ! target e that produced P_DAMPING, or -1; never read here
   integer, parameter :: P_CLIP = 5        ! kelvin only: > 0.5 means F = max(0, k delta + c ddelta)
   !> Hertz (1882): n = 3/2 for smooth bodies; the exponent of the laws that read P_EXPONENT
   !> when the caller gives none.
   real(dp), parameter :: HERTZ_EXPONENT = 1.5_dp

   real(dp), parameter :: PI = 3.14159265358979323846264338327950288_dp
   real(dp), parameter :: THREE_HALVES = 1.5_dp

   ! Below this a the exact-HC residual is summed as a series: the closed form cancels to
   ! O(a^2) from O(a) terms and would lose log10(1/a) digits.
   real(dp), parameter :: A_SERIES = 0.2_dp

contains

   !> Contact force and its partial derivatives df/d(delta), df/d(ddelta).
   !> Exponents: linear and kelvin use n = 1, Jankowski and hertzdamp the published n = 3/2
   !> (par(P_EXPONENT) is ignored for these four); hertz, Hunt-Crossley, Lankarani-Nikravesh,
   !> Flores and Gonthier use n = par(P_EXPONENT).
   !> v_in is the approach speed at the onset of the current contact phase, used only by
   !> the HC family (chi = a/v_in); it must be > 0 there unless a = 0. mstar is the contact's
   !> effective mass 1/(B M⁻¹ Bᵀ), read only by Jankowski.
   pure subroutine contact_force(law, par, mstar, delta, ddelta, v_in, f, df_ddelta, df_dddelta)
      integer, intent(in) :: law
      real(dp), intent(in) :: par(NPAR_CONTACT)
      real(dp), intent(in) :: mstar, delta, ddelta, v_in
      real(dp), intent(out) :: f, df_ddelta, df_dddelta
      real(dp) :: k, n, c, chi, fel, dfel, fac, root4, cj

      f = 0.0_dp
      df_ddelta = 0.0_dp
      df_dddelta = 0.0_dp
      if (.not. law_is_known(law)) then
         f = nan()
         df_ddelta = f
         df_dddelta = f
         return
      end if
      if (delta <= 0.0_dp) return

      k = par(P_STIFF)
      select case (law)
      case (LAW_LINEAR)
         f = k*delta
         df_ddelta = k

      case (LAW_HERTZ)
         n = par(P_EXPONENT)
         f = k*delta**n
         df_ddelta = n*k*delta**(n - 1.0_dp)

      case (LAW_KELVIN)
         ! Anagnostopoulos (1988): linear spring + dashpot; the clipped variant removes the
         ! tension that the unclipped law develops just before separation (docs/problems.md P5).
         c = par(P_DAMPING)
         f = k*delta + c*ddelta
         df_ddelta = k
         df_dddelta = c
         if (par(P_CLIP) > 0.5_dp .and. f <= 0.0_dp) then
            f = 0.0_dp
            df_ddelta = 0.0_dp
            df_dddelta = 0.0_dp
         end if

      case (LAW_HUNT_CROSSLEY, LAW_LANKARANI_NIKRAVESH, LAW_FLORES, LAW_GONTHIER, LAW_HERTZDAMP)
         ! Hunt & Crossley (1975): F = K delta^n (1 + chi ddelta), chi = a / v_in.
         if (law == LAW_HERTZDAMP) then
            n = THREE_HALVES   ! Muthukumar & DesRoches (2006): Hertz exponent
         else
            n = par(P_EXPONENT)
         end if
         if (v_in > 0.0_dp) then
            chi = par(P_DAMPING)/v_in
         else if (abs(par(P_DAMPING)) > 0.0_dp) then
            f = nan()          ! chi = a/v_in undefined: the caller must supply v_in > 0
            df_ddelta = f
            df_dddelta = f
            return
         else
            chi = 0.0_dp       ! undamped: v_in irrelevant
         end if
         fac = 1.0_dp + chi*ddelta
         if (fac <= 0.0_dp) return   ! would pull: clipped at F = 0
         fel = k*delta**n
         dfel = n*k*delta**(n - 1.0_dp)
         f = fel*fac
         df_ddelta = dfel*fac
         df_dddelta = fel*chi

      case (LAW_JANKOWSKI)
         ! Jankowski (EESD 2005): F = beta delta^(3/2) + c ddelta while approaching,
         ! c = 2 xi sqrt(beta sqrt(delta) m*); elastic only while restoring (ddelta <= 0).
         f = k*delta**THREE_HALVES
         df_ddelta = THREE_HALVES*k*sqrt(delta)
         if (ddelta > 0.0_dp) then
            root4 = sqrt(sqrt(delta))
            cj = 2.0_dp*par(P_DAMPING)*sqrt(k*mstar)   ! c = cj * delta^(1/4)
            f = f + cj*root4*ddelta
            df_ddelta = df_ddelta + 0.25_dp*cj*ddelta/(root4*root4*root4)
            df_dddelta = cj*root4
         end if
      end select
   end subroutine contact_force

   !> Recoverable energy of the elastic part, K delta^(n+1)/(n+1), with the same exponent
   !> as contact_force uses for the law (0 for delta <= 0).
   pure function contact_elastic_energy(law, par, delta) result(e)
      integer, intent(in) :: law
      real(dp), intent(in) :: par(NPAR_CONTACT)
      real(dp), intent(in) :: delta
      real(dp) :: e
      real(dp) :: n

      if (.not. law_is_known(law)) then
         e = nan()
         return
      end if
      e = 0.0_dp
      if (delta <= 0.0_dp) return
      n = law_exponent(law, par)
      e = par(P_STIFF)*delta**(n + 1.0_dp)/(n + 1.0_dp)
   end function contact_elastic_energy

   !> The law's own published damping for a target restitution e, i.e. the value to store
   !> in par(P_DAMPING). Only the Kelvin result is exact (for the unclipped law); for the HC
   !> family use exact_hc_factor to realise e exactly.
   !>  linear, hertz: 0 for any e (they cannot dissipate: they always realise e = 1);
   !>  kelvin: c [N s/m], needs par(P_STIFF) and the effective mass mstar; e in [0, 1];
   !>          e = 0 is taken as the limit xi -> 1 (critical damping, c = 2 sqrt(k m*)): the
   !>          unclipped law then never separates, i.e. e = 0 is reached only asymptotically;
   !>  HC family: the dimensionless a = chi*v_in; e in [0, 1] for HC, LN and hertzdamp,
   !>          e in (0, 1] for Flores and Gonthier (they divide by e);
   !>  Jankowski: xi [-]; e in (0, 1].
   !> Out-of-range e gives NaN.
   pure function damping_from_restitution(law, e, par, mstar) result(d)
      integer, intent(in) :: law
      real(dp), intent(in) :: e, mstar
      real(dp), intent(in) :: par(NPAR_CONTACT)
      real(dp) :: d
      real(dp) :: lne, xi

      d = nan()
      if (.not. law_is_known(law)) return
      if (.not. (e >= 0.0_dp .and. e <= 1.0_dp)) return   ! also rejects NaN
      select case (law)
      case (LAW_LINEAR, LAW_HERTZ)
         d = 0.0_dp
      case (LAW_KELVIN)
         ! Anagnostopoulos (1988): xi = -ln e / sqrt(pi^2 + ln^2 e), c = 2 xi sqrt(k m*)
         if (e <= 0.0_dp) then
            xi = 1.0_dp        ! limit of the formula as ln e -> -infinity
         else
            lne = log(e)
            xi = -lne/sqrt(PI*PI + lne*lne)
         end if
         d = 2.0_dp*xi*sqrt(par(P_STIFF)*mstar)
      case (LAW_HUNT_CROSSLEY)
         d = 1.5_dp*(1.0_dp - e)                          ! Hunt & Crossley (1975)
      case (LAW_LANKARANI_NIKRAVESH, LAW_HERTZDAMP)
         d = 0.75_dp*(1.0_dp - e)*(1.0_dp + e)            ! Lankarani & Nikravesh (1990)
      case (LAW_FLORES)
         if (e > 0.0_dp) d = 1.6_dp*(1.0_dp - e)/e        ! Flores et al. (2011): 8(1-e)/(5e)
      case (LAW_GONTHIER)
         if (e > 0.0_dp) d = (1.0_dp - e)*(1.0_dp + e)/e  ! Gonthier et al. (2004)
      case (LAW_JANKOWSKI)
         ! Jankowski (2005, 2006): xi = (9 sqrt5/2)(1-e^2)/(e(e(9 pi - 16) + 16))
         if (e > 0.0_dp) d = 4.5_dp*sqrt(5.0_dp)*(1.0_dp - e)*(1.0_dp + e) &
                             /(e*(e*(9.0_dp*PI - 16.0_dp) + 16.0_dp))
      end select
   end function damping_from_restitution

   !> The factor a = chi*v0 for which the Hunt-Crossley form F = K delta^n (1 + chi ddelta)
   !> realises restitution e exactly: the root in (0, 1/e) of (1 + e) a = ln[(1 + a)/(1 - e a)]
   !> (docs/problems.md P5; independent of n, K and m*). e = 1 gives 0; e must be in (0, 1]
   !> (a -> infinity as e -> 0); otherwise NaN.
   !> Solved by bisection to round-off in t = -ln(1 - e a) in (0, (1+e)/e + 1): a(t) stays
   !> below 1/e even when 1 - e a is below round-off (small e, a = 1/e to working precision).
   elemental function exact_hc_factor(e) result(a)
      real(dp), intent(in) :: e
      real(dp) :: a
      real(dp) :: lo, hi, mid
      integer :: it

      if (.not. (e > 0.0_dp .and. e <= 1.0_dp)) then
         a = nan()
         return
      end if
      if (e >= 1.0_dp) then
         a = 0.0_dp
         return
      end if
      ! Residual < 0 as t -> 0+ (it tends to (e^2 - 1)/2 after division by a^2) and >= 1 at
      ! hi, because ln(1 + a) >= 0 and (1 + e) a <= (1 + e)/e there; the root is unique.
      lo = 0.0_dp
      hi = (1.0_dp + e)/e + 1.0_dp
      do it = 1, 2000   ! ~110 halvings reach round-off; the cap only guards the loop
         mid = 0.5_dp*(lo + hi)
         if (mid <= lo .or. mid >= hi) exit
         if (hc_residual(mid, e) < 0.0_dp) then
            lo = mid
         else
            hi = mid
         end if
      end do
      a = -expm1_dp(-0.5_dp*(lo + hi))/e
   end function exact_hc_factor

   elemental logical function law_is_known(law)
      integer, intent(in) :: law
      law_is_known = law >= LAW_LINEAR .and. law <= LAW_JANKOWSKI
   end function law_is_known

   !> Exponent of the elastic part, consistent with contact_force: fixed by the law, or
   !> par(P_EXPONENT) for the laws that read it.
   pure function law_exponent(law, par) result(n)
      integer, intent(in) :: law
      real(dp), intent(in) :: par(NPAR_CONTACT)
      real(dp) :: n
      select case (law)
      case (LAW_LINEAR, LAW_KELVIN)
         n = 1.0_dp
      case (LAW_HERTZDAMP, LAW_JANKOWSKI)
         n = THREE_HALVES
      case default
         n = par(P_EXPONENT)
      end select
   end function law_exponent

   !> Whether the law's force on the contact side is K delta^n with a whole n >= 1 and
   !> coefficients the law's own (linear; Hertz with a whole exponent): a polynomial in delta,
   !> so along a motion through the onset every derivative of the force is bounded on each side,
   !> the force is continuous and its rate jumps by a finite amount (k times the approach speed
   !> for n = 1, 0 above). Not so: a fractional exponent (K delta^(3/2): the second derivative
   !> K (3/4) delta^(-1/2) delta'^2 is unbounded at the onset), the Hunt-Crossley family (its
   !> damping chi = a/v_in takes the approach speed at the onset, known only once the onset is
   !> located), Kelvin (the force jumps by c delta') and Jankowski (damping ~ delta^(1/4)).
   !> docs/sundials-ode.md, events inside the steps.
   pure logical function law_rate_bounded(law, par)
      integer, intent(in) :: law
      real(dp), intent(in) :: par(NPAR_CONTACT)
      real(dp) :: n
      law_rate_bounded = .false.
      if (law /= LAW_LINEAR .and. law /= LAW_HERTZ) return
      n = law_exponent(law, par)
      law_rate_bounded = n >= 1.0_dp .and. n == aint(n)
   end function law_rate_bounded

   ! ---------------------------------------------------------------- private helpers

   !> A quantity with the sign of (ln(1+a) - ln(1-e a) - (1+e) a), a = (1 - exp(-t))/e.
   !> Large a: the closed form with t = -ln(1 - e a) exactly. Small a: the series of the
   !> same expression divided by a^2, sum_{k>=2} c_k a^(k-2)/k with
   !> c_k = e^k + (-1)^(k+1), where e^k - 1 = -(1-e)(1 + e + ... + e^(k-1)) avoids the
   !> cancellation when e is close to 1.
   pure function hc_residual(t, e) result(r)
      real(dp), intent(in) :: t, e
      real(dp) :: r
      real(dp) :: a, d, p, s, apow, ck, term, scale
      integer :: k

      a = -expm1_dp(-t)/e
      if (a > A_SERIES) then
         r = log1p_dp(a) + t - (1.0_dp + e)*a
         return
      end if
      d = 1.0_dp - e          ! exact for e >= 1/2 (Sterbenz): every e whose root is here
      p = e                   ! e^(k-1)
      s = 1.0_dp              ! 1 + e + ... + e^(k-2)
      apow = 1.0_dp           ! a^(k-2)
      scale = d               ! |c_2|/2 ~ d sets the size of the sum's leading terms
      r = 0.0_dp
      do k = 2, 400
         p = p*e
         s = 1.0_dp + e*s
         if (mod(k, 2) == 0) then
            ck = -d*s
         else
            ck = p + 1.0_dp
         end if
         term = ck*apow/real(k, dp)
         r = r + term
         if (k > 3 .and. abs(term) <= 0.01_dp*epsilon(1.0_dp)*scale) exit
         apow = apow*a
      end do
   end function hc_residual

   !> log(1 + x) accurate for small |x|, x > -1 (not intrinsic in F2008). Goldberg's
   !> correction log(u) x/(u - 1), u = fl(1 + x), cancels the rounding of u; for
   !> |x| < 1e-10 (where u - 1 may vanish) the cubic Taylor polynomial is exact to ~1e-40.
   pure function log1p_dp(x) result(y)
      real(dp), intent(in) :: x
      real(dp) :: y, u
      if (abs(x) < 1.0e-10_dp) then
         y = x*(1.0_dp - x*(0.5_dp - x/3.0_dp))
      else
         u = 1.0_dp + x
         y = log(u)*x/(u - 1.0_dp)
      end if
   end function log1p_dp

   !> exp(x) - 1 accurate for small |x| (not intrinsic in F2008): Kahan's (u - 1) x/log(u),
   !> u = fl(exp(x)); cubic Taylor for |x| < 1e-10; -1 below x = -40.
   pure function expm1_dp(x) result(y)
      real(dp), intent(in) :: x
      real(dp) :: y, u
      if (abs(x) < 1.0e-10_dp) then
         y = x*(1.0_dp + x*(0.5_dp + x/6.0_dp))
      else if (x < -40.0_dp) then
         y = -1.0_dp            ! exp(-40) ~ 4e-18 is below half an ulp of 1
      else
         u = exp(x)
         y = (u - 1.0_dp)*x/log(u)
      end if
   end function expm1_dp

   pure function nan() result(x)
      real(dp) :: x
      x = ieee_value(1.0_dp, ieee_quiet_nan)
   end function nan

end module martello_contact_laws
