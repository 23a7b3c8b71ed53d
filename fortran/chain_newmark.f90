!> The fused chain step (docs/run-layer.md "The fused chain step"): Newmark (β, γ) on a chain,
!> a scene whose effective stiffness is tridiagonal (every link and contact couples nodes i
!> and i ± 1, or a node and ground; lumped masses) and whose laws are piecewise linear
!> (springs, bars, dashpots, bilinear springs; linear and Kelvin penalty contacts).
!>
!> Newton's method on the step equations, as the general path (martello_generalized_alpha)
!> does, but on such a scene one Newton step from a state is exact as long as no law changes
!> branch between the linearisation and the new iterate. The scene is held per node
!> (structure of arrays): the linear links of a node to ground and of a node pair summed, the
!> first contact of each pair with its law resolved once for all pairs; the other elements
!> (bilinear springs, contacts to ground, a second contact on a pair) one by one. A step is a
!> forward sweep (the residual at u = uₙ linearised about the committed state, forward
!> substitution with the kept factors J = L D Lᵀ, reciprocal pivots) and a backward sweep that
!> solves for Δu, updates u, v, a by the Newmark relations and evaluates the elements of each
!> node and pair as it goes (forces, branches, works). If no law changed branch the step has
!> converged, to round-off, with no further solve; otherwise J is factorised on the new
!> branches and Newton goes on. A step that does not settle in MAX_FUSED solves, or meets a
!> pivot ≤ 0, is taken by the general path (line search, chatter rule, its failure
!> messages): the answers are the general path's, to its Newton tolerance. The step measures
!> itself (measures_itself): node peaks, contact phases and maxima go to the observer from its
!> measuring pass, item by item.
module martello_chain_newmark
   use, intrinsic :: iso_fortran_env, only: int8
   use martello_kinds, only: dp, i8
   use martello_status
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use martello_model, only: model_t, model_bandwidth, SCHEME_PENALTY, model_link_index, &
      model_initial_state, &
      model_contact_index, model_link_at, model_contact_at, model_expand_chains, model_nlinks, &
      model_ncontacts, model_has_influence
   use martello_links, only: LINK_SPRING, LINK_BAR, LINK_DASHPOT, LINK_BILINEAR, L_STIFF, L_DAMP, &
      L_YIELD, L_HARDENING, bilinear_return_map, bilinear_energy
   use martello_contact_laws, only: LAW_LINEAR, LAW_KELVIN, P_STIFF, P_DAMPING, P_CLIP, &
      P_RESTITUTION, NPAR_CONTACT, contact_elastic_energy, damping_from_restitution
   use martello_links, only: NPAR_LINK
   use martello_effective_mass, only: pair_effective_mass, effective_mass_prepare
   use martello_assembly, only: external_forces, uniform_acceleration, internal_forces, mech_commit
   use martello_time_functions, only: tf_value
   use martello_observer, only: observer_t, observer_fail, observer_failed, observer_work, observer_begin, observer_sample, &
      observer_open_phase, observer_node_samples, observer_node_turns, &
      observer_node_step_extrema, observer_phase_change, observer_contact_peaks, &
      observer_phase_peaks, observer_energy_due, observer_recorded, tracks, TRACK_NODE_PEAKS, TRACK_ALL, &
      TRACK_LINK_PEAKS, TRACK_CONTACT_PEAKS, TRACK_PHASES, observer_a_parabolas, &
      observer_a_candidate, observer_contact_step_peaks, observer_step_absmax, &
      observer_link_step_extremum, raise_to
   use martello_run_quantities, only: C_NEWTON, C_RESIDUALS, C_FACTORIZATIONS, C_JACOBIANS, C_FUSED
   use martello_integrator_settings, only: integrator_settings_t, INT_NEWMARK
   use martello_fixed_step, only: stepper_t
   use martello_generalized_alpha, only: generalized_alpha_t
   implicit none
   private
   public :: chain_newmark_t, chain_fusable

   !> Fused Newton iterations before a step is handed to the general path: a step whose
   !> branches have not settled after this many exact linear solves is a chattering one.
   integer, parameter :: MAX_FUSED = 8

   !> Branches of the piecewise-linear laws (the tangent is constant on each).
   integer(int8), parameter :: B_OFF = 0, B_ON = 1, B_CLIPPED = 2, B_ELASTIC = 0, B_UPPER = 1, &
                               B_LOWER = -1
   !> Laws of the pair contacts
   integer(int8), parameter :: K_LINEAR = 1, K_KELVIN = 2, K_KELVIN_CLIPPED = 3

   type, extends(stepper_t) :: chain_newmark_t
      type(integrator_settings_t) :: settings
      !> Newmark: Δa = c_m Δu, Δv = c_v Δu; the iterate u = uₙ has a₀ = −c₁vₙ − c₂aₙ
      real(dp) :: beta = 0.25_dp, gamma = 0.5_dp, cm = 0.0_dp, cv = 0.0_dp, c1 = 0.0_dp, &
                  c2 = 0.0_dp
      !> the masses, read at 1 + (i − 1)·sm: one value for every node (sm = 0) or each's
      real(dp), allocatable :: mass(:)
      integer :: sm = 1
      !> the linear links (springs, bars, dashpots) summed: of node i to ground (kg, cg,
      !> 1:n), of the pair (i, i+1) (kp, cp, 0:n with 0 and n zero; allocated if any)
      real(dp), allocatable :: kg(:), cg(:), kp(:), cp(:)
      logical :: pair_links = .false.
      !> the links are those of the model's one chain on every node, dashpots included: kg and
      !> cg are its k and c, read there (no copy)
      logical :: chain_links = .false.
      !> the pair contact of (i, i+1), i < n: δ = s(u_i − u_{i+1}) − gap with s = ±1,
      !> force k δ (+ c δ̇ for Kelvin). Parameter arrays run from 0 and are read at i·stride:
      !> stride 0 when every pair has the same value (one value for the chain).
      logical :: pair_contacts = .false., kelvin = .false.
      !> contact index of pair i (0: none); pc0 ≥ 0: pair i has contact pc0 + i (pcon unused)
      integer, allocatable :: pcon(:)
      integer :: pc0 = -1
      real(dp), allocatable :: psgn(:), pgap(:), pk(:), pc(:)
      integer(int8), allocatable :: plaw(:)
      integer :: ss = 0, sg = 0, sk = 0, sc = 0, sl = 0
      !> pair contact branches: trial (of the last evaluation), committed, of the factors
      integer(int8), allocatable :: pbr(:), pbrc(:), pbrf(:)
      !> the other elements, one by one (of those added one by one: model_add_link and
      !> model_add_contact): bilinear links (their index there, blo among all the model's
      !> links; committed force and elongation, trial, branch of the last evaluation and of
      !> the factors) and the other contacts (xg there, xc among all the contacts; branches)
      integer, allocatable :: bl(:), blo(:), xg(:), xc(:)
      real(dp), allocatable :: bfc(:), bdu(:), bft(:), bdut(:)
      integer(int8), allocatable :: bbr(:), bbrf(:), xbr(:), xbrc(:), xbrf(:)
      !> their tangents on the factors' branches per node: J (diagonal, J(i, i+1)) and C_t
      real(dp), allocatable :: xjd(:), xjo(:), xcd(:), xco(:)
      logical :: others = .false.
      !> J = L D Lᵀ: reciprocal pivots rp(i) = 1/D_ii (L(i+1, i) = J(i, i+1)·rp(i) is computed
      !> again where a sweep needs it, coupling: no array of it); fe the nodal internal force
      !> at the last evaluation minus the nodal forces (fnod, as applied), which the forward
      !> sweeps overwrite, entry by entry as they read it, with the forward-substituted
      !> right-hand side y, and the backward sweep, entry by entry after reading y, with the
      !> internal force again: one array for both
      real(dp), allocatable :: rp(:), fe(:), fnod(:)
      !> a node is fixed (its row and column of J are the identity's)
      logical :: any_fixed = .false.
      logical :: factored = .false.
      !> the link peaks, per node (links to ground: max |u_i|, |v_i|) and per pair (max |Δu|,
      !> |Δv|) over the samples: each link's follows from its parameter (link_peaks)
      real(dp), allocatable :: gumax(:), gvmax(:), pumax(:), pvmax(:)
      !> Σ m_i Δu_i of the step, and the uniform load acceleration at its start and end: the
      !> external work ½(a_n + a)·Σ m_i Δu_i (docs/run-layer.md) without a pass of its own
      real(dp) :: mdu = 0.0_dp, acc_n = 0.0_dp, acc = 0.0_dp
      !> trapezoidal works of the last evaluation (dampers, other links, contacts)
      real(dp) :: wd = 0.0_dp, wl = 0.0_dp, wc = 0.0_dp
      !> the general path, made at the first step handed to it, and the model with its chains
      !> as links and contacts one by one, for it (when the model has chains)
      type(generalized_alpha_t), allocatable :: gen
      type(model_t), allocatable :: gm
   contains
      procedure :: from_chain_of_one_kind
      procedure :: init => chain_init
      procedure :: step => chain_step
      procedure :: begin_step => chain_begin_step
      procedure :: measure_start => chain_measure_start
      procedure :: measure => chain_measure
   end type chain_newmark_t

contains

   !> Whether the fused step runs this scene with these settings: Newmark with 2β ≥ γ
   !> (unconditionally stable: no stability limit to check), fused_chain on, a tridiagonal
   !> stiffness (half-bandwidth ≤ 1), lumped masses, piecewise-linear links and penalty
   !> contacts with the linear or Kelvin law, no stiffness block. Everything else takes the
   !> general path.
   logical function chain_fusable(m, s) result(ok)
      type(model_t), intent(in) :: m
      type(integrator_settings_t), intent(in) :: s
      integer :: j, q
      logical, allocatable :: paired(:)
      ok = s%kind == INT_NEWMARK .and. logical(s%fused_chain) .and. 2.0_dp*s%beta >= s%gamma
      if (.not. ok) return
      ! stiffness blocks (frames) are not in the sweep's per-node parameters
      ok = model_bandwidth(m) <= 1 .and. m%ncoupling == 0 .and. m%nblock == 0 &
           .and. .not. model_has_influence(m)     ! the sweep loads every node with its mass
      do j = 1, m%nlink
         select case (m%link_kind(j))
         case (LINK_SPRING, LINK_BAR, LINK_DASHPOT, LINK_BILINEAR)
         case default
            ok = .false.
         end select
      end do
      do j = 1, m%ncontact
         if (m%con_scheme(j) /= SCHEME_PENALTY) ok = .false.
         if (m%con_law(j) /= LAW_LINEAR .and. m%con_law(j) /= LAW_KELVIN) ok = .false.
      end do
      ! a chain held per node: linear springs (its bilinear ones are taken one by one), and
      ! contacts the sweep holds as pair contacts (one chain's to a pair)
      ! a scene whose few bytes per node cannot be had is not fused (the general path then
      ! reports its own out-of-memory line)
      allocate (paired(0:m%n), stat=j)
      if (j /= 0) then
         ok = .false.; return
      end if
      paired = .false.
      do q = 1, m%nchain
         associate (ch => m%chain(q))
            if (allocated(ch%fy)) ok = .false.
            if (ch%ncontact == 0) cycle
            if (ch%scheme /= SCHEME_PENALTY) ok = .false.
            if (ch%law /= LAW_LINEAR .and. ch%law /= LAW_KELVIN) ok = .false.
            if (any(paired(ch%first:ch%first + ch%n - 2))) ok = .false.
            paired(ch%first:ch%first + ch%n - 2) = .true.
         end associate
      end do
   end function chain_fusable

   !> The scene per node, and the state at t = 0 with a = M⁻¹(f_ext − f_int).
   subroutine chain_init(self, m, s, o, stat)
      class(chain_newmark_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      type(integrator_settings_t), intent(in) :: s
      type(observer_t), intent(inout) :: o
      integer, intent(out) :: stat
      integer :: n, i, st
      logical :: flipped
      character(len=16) :: num
      character(len=512) :: msg
      stat = MARTELLO_OK
      n = m%n
      self%n = n; self%nc = m%ncontact; self%h = s%dt; self%settings = s
      self%beta = s%beta; self%gamma = s%gamma
      self%cm = 1.0_dp/(s%beta*s%dt*s%dt); self%cv = s%gamma/(s%beta*s%dt)
      self%c1 = 1.0_dp/(s%beta*s%dt); self%c2 = (0.5_dp - s%beta)/s%beta
      self%sm = merge(0, 1, all(m%mass == m%mass(1)))
      self%advice = 'the step is past the stability limit'
      self%measures_itself = .true.
      ! st: every allocation of the per-node state (stat > 0 if one failed)
      allocate (self%mass(merge(1, n, self%sm == 0)), self%fixed_nodes(count(m%fixed)), &
                self%u(0:n), self%v(0:n), self%a(0:n), self%un(0:n), self%vn(0:n), self%an(0:n), &
                self%pen(0), self%force(0), self%rp(n), self%fe(0:n), self%fnod(m%nforce), stat=st)
      if (st == 0) call per_node(self, m, st)
      if (st == 0) call link_peak_arrays(self, m, tracks(o, TRACK_LINK_PEAKS), st)
      if (st /= 0) then
         write (num, '(i0)') n
         call out_of_memory('the per-node state of the fused chain step for '//trim(num)//' nodes', &
                            -1.0_dp, FIX_SMALLER_SCENE, stat, msg)
         call observer_fail(o, MARTELLO_ERR_MEMORY, 0.0_dp, msg, stat)
         return
      end if
      self%mass = m%mass(1:size(self%mass))
      self%u(0) = 0.0_dp; self%v(0) = 0.0_dp
      call model_initial_state(m, self%u(1:n), self%v(1:n))
      self%fixed_nodes = pack([(i, i = 1, n)], m%fixed)
      ! the bilinear springs start elastic, on k·Δu₀ (clamped into the band by the first
      ! step), as mech_init
      do i = 1, size(self%bl)
         self%bdu(i) = self%u(m%link_a(self%bl(i))) - self%u(m%link_b(self%bl(i)))
         self%bfc(i) = m%link_par(L_STIFF, self%bl(i))*self%bdu(i)
      end do
      self%rp = 0.0_dp; self%fe = 0.0_dp; self%fnod = 0.0_dp
      self%any_fixed = size(self%fixed_nodes) > 0
      ! the elements at (u0, v0) with their whole laws: the evaluation at an iterate with no
      ! increment, works from (u0, v0) itself
      self%un = self%u; self%vn = self%v; self%a = 0.0_dp; self%an = 0.0_dp
      self%acc = uniform_acceleration(m, 0.0_dp)
      call evaluate(self, m, .false., flipped)
      call nodal_forces(self, m, 0.0_dp)
      ! M a = f_ext − f_int on the free nodes: M is diagonal (counted as the general path's
      ! factorisation of M)
      do i = 1, n
         self%a(i) = 0.0_dp
         if (.not. m%fixed(i)) self%a(i) = (m%mass(i)*self%acc - self%fe(i))/m%mass(i)
      end do
      o%counters(C_FACTORIZATIONS) = o%counters(C_FACTORIZATIONS) + 1_i8
      call commit(self)
      self%un = self%u; self%vn = self%v; self%an = self%a
      self%factored = .false.
   end subroutine chain_init

   !> The chain per node from the model's links and contacts (chain_fusable holds): the
   !> linear links summed per node and per pair, the first contact of each pair in the pair
   !> arrays (one value for the chain where all pairs share it), the rest one by one.
   !> st > 0: an allocation failed (the state is then incomplete).
   subroutine per_node(self, m, st)
      class(chain_newmark_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      integer, intent(out) :: st
      integer :: n, j, a, b, lo, nb, nx, q, i, c
      real(dp) :: k, cd
      logical, allocatable :: pair(:)
      n = m%n
      self%chain_links = m%nchain == 1 .and. m%nlink == 0
      if (self%chain_links) self%chain_links = m%chain(1)%first == 1 .and. m%chain(1)%n == n .and. &
                                               allocated(m%chain(1)%c)
      allocate (self%kg(merge(0, n, self%chain_links)), self%cg(merge(0, n, self%chain_links)), &
                self%pcon(0:n), pair(m%ncontact), self%pbr(0:n), self%pbrc(0:n), self%pbrf(0:n), &
                stat=st)
      if (st /= 0) return
      self%kg = 0.0_dp; self%cg = 0.0_dp
      self%pair_links = .false.
      do j = 1, m%nlink
         a = m%link_a(j); b = m%link_b(j)
         if (m%link_kind(j) /= LINK_BILINEAR .and. a > 0 .and. b > 0) self%pair_links = .true.
      end do
      ! unused ones hold one entry: the kernels take them as arrays
      allocate (self%kp(0:merge(n, 0, self%pair_links)), self%cp(0:merge(n, 0, self%pair_links)), &
                stat=st)
      if (st /= 0) return
      self%kp = 0.0_dp; self%cp = 0.0_dp
      nb = 0
      do j = 1, m%nlink
         a = m%link_a(j); b = m%link_b(j)
         k = 0.0_dp; cd = 0.0_dp
         select case (m%link_kind(j))
         case (LINK_SPRING, LINK_BAR)
            k = m%link_par(L_STIFF, j)
         case (LINK_DASHPOT)
            cd = m%link_par(L_DAMP, j)
         case default
            nb = nb + 1; cycle
         end select
         if (a > 0 .and. b > 0) then
            lo = min(a, b)
            self%kp(lo) = self%kp(lo) + k; self%cp(lo) = self%cp(lo) + cd
         else
            self%kg(a + b) = self%kg(a + b) + k; self%cg(a + b) = self%cg(a + b) + cd
         end if
      end do
      ! the chains' springs and dashpots (chain_fusable: linear)
      do q = merge(m%nchain + 1, 1, self%chain_links), m%nchain
         associate (ch => m%chain(q))
            do i = 1, ch%n
               j = ch%first + i - 1
               self%kg(j) = self%kg(j) + ch%k(i)
               if (allocated(ch%c)) self%cg(j) = self%cg(j) + ch%c(i)
            end do
         end associate
      end do
      self%bl = pack([(j, j = 1, m%nlink)], m%link_kind(1:m%nlink) == LINK_BILINEAR)
      self%blo = [(model_link_index(m, self%bl(j)), j = 1, nb)]
      allocate (self%bfc(nb), self%bdu(nb), self%bft(nb), self%bdut(nb), self%bbr(nb), &
                self%bbrf(nb), stat=st)
      if (st /= 0) return
      self%bbr = B_ELASTIC; self%bbrf = B_ELASTIC
      ! the pair contacts: the chains' (chain_fusable: one to a pair), then the first contact
      ! added one by one between i and i + 1; numbered among all the model's contacts
      self%pcon = 0; pair = .false.
      do q = 1, m%nchain
         associate (ch => m%chain(q))
            do i = 1, ch%ncontact
               self%pcon(ch%first + i - 1) = ch%contact0 + i
            end do
         end associate
      end do
      do j = 1, m%ncontact
         a = m%con_a(j); b = m%con_b(j)
         if (a == 0 .or. b == 0) cycle
         lo = min(a, b)
         if (self%pcon(lo) == 0) then
            self%pcon(lo) = model_contact_index(m, j); pair(j) = .true.
         end if
      end do
      self%pair_contacts = any(self%pcon > 0)
      call pair_parameters(self, m, st)
      if (st /= 0) return
      if (n > 1) then
         c = self%pcon(1)
         if (c > 0 .and. all(self%pcon(1:n - 1) == [(c - 1 + j, j = 1, n - 1)])) self%pc0 = c - 1
      end if
      if (self%pc0 >= 0) then
         deallocate (self%pcon); allocate (self%pcon(0:0), stat=st); self%pcon = 0
      end if
      self%pbr = B_OFF; self%pbrc = B_OFF; self%pbrf = B_OFF
      self%xg = pack([(j, j = 1, m%ncontact)], .not. pair)
      nx = size(self%xg)
      self%xc = [(model_contact_index(m, self%xg(j)), j = 1, nx)]
      allocate (self%xbr(nx), self%xbrc(nx), self%xbrf(nx), stat=st)
      if (st /= 0) return
      self%xbr = B_OFF; self%xbrc = B_OFF; self%xbrf = B_OFF
      self%others = nb > 0 .or. nx > 0
      nx = merge(n, 0, self%others)
      allocate (self%xjd(0:nx), self%xjo(0:nx), self%xcd(0:nx), self%xco(0:nx), stat=st)
      if (st /= 0) return
      self%xjd = 0.0_dp; self%xjo = 0.0_dp; self%xcd = 0.0_dp; self%xco = 0.0_dp
   end subroutine per_node

   !> The pair contacts' parameters: sign, gap, stiffness, damping and law, each one value for
   !> the chain (stride 0) where every pair has a contact and they share it.
   subroutine pair_parameters(self, m, st)
      class(chain_newmark_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      integer, intent(out) :: st
      integer :: n, i, j, a, b, scheme, claw
      real(dp), allocatable :: sgn(:), gap(:), k(:), c(:)
      real(dp) :: par(NPAR_CONTACT), mstar
      integer(int8), allocatable :: law(:)
      logical :: every
      n = m%n
      allocate (sgn(0:n), gap(0:n), k(0:n), c(0:n), law(0:n), stat=st)
      if (st /= 0) return
      ! a pair without a contact: a gap no motion closes
      sgn = 1.0_dp; gap = huge(1.0_dp); k = 0.0_dp; c = 0.0_dp; law = K_LINEAR
      do i = 1, n - 1
         j = self%pcon(i)
         if (j == 0) cycle
         call model_contact_at(m, j, a, b, gap(i), scheme, claw, par)
         sgn(i) = merge(1.0_dp, -1.0_dp, a == i)
         k(i) = par(P_STIFF)
         if (claw == LAW_KELVIN) then
            ! the damping of a target restitution, with the pair's m* (as
            ! effective_mass_prepare gives the contacts added one by one)
            c(i) = par(P_DAMPING)
            if (par(P_RESTITUTION) >= 0.0_dp) then
               mstar = pair_effective_mass(m, a, b)
               c(i) = 0.0_dp
               if (ieee_is_finite(mstar)) c(i) = damping_from_restitution(claw, &
                                                                          par(P_RESTITUTION), par, mstar)
            end if
            law(i) = merge(K_KELVIN_CLIPPED, K_KELVIN, par(P_CLIP) > 0.5_dp)
         end if
      end do
      self%kelvin = any(law(1:n - 1) /= K_LINEAR)
      every = n > 1 .and. all(self%pcon(1:n - 1) > 0)
      call one_or_all(sgn, self%psgn, self%ss)
      if (st == 0) call one_or_all(gap, self%pgap, self%sg)
      if (st == 0) call one_or_all(k, self%pk, self%sk)
      if (st == 0) call one_or_all(c, self%pc, self%sc)
      if (st /= 0) return
      if (every .and. all(law(1:n - 1) == law(1))) then
         allocate (self%plaw(0:0), stat=st); self%plaw(0) = law(1); self%sl = 0
      else
         call move_alloc(law, self%plaw); self%sl = 1
      end if
   contains
      !> x(0:n) as one value at index 0 (stride 0) if pairs 1 … n−1 all have a contact and
      !> share it, else whole (stride 1).
      subroutine one_or_all(x, to, stride)
         real(dp), allocatable, intent(inout) :: x(:)
         real(dp), allocatable, intent(out) :: to(:)
         integer, intent(out) :: stride
         if (every .and. all(x(1:n - 1) == x(1))) then
            allocate (to(0:0), stat=st); if (st /= 0) return
            to(0) = x(1); stride = 0
         else
            allocate (to(0:n), stat=st); if (st /= 0) return
            to(0:n) = x; stride = 1
         end if
      end subroutine one_or_all
   end subroutine pair_parameters

   !> The per-node and per-pair maxima the link peaks need: only for the kinds the chain has.
   subroutine link_peak_arrays(self, m, tracked, st)
      class(chain_newmark_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      logical, intent(in) :: tracked
      integer, intent(out) :: st
      integer :: j, n
      logical :: ground, gdamp, pair, pdamp
      n = merge(m%n, 0, tracked)
      ground = .false.; gdamp = .false.; pair = .false.; pdamp = .false.
      do j = 1, m%nlink
         if (m%link_kind(j) == LINK_BILINEAR) cycle
         if (m%link_a(j) > 0 .and. m%link_b(j) > 0) then
            pair = .true.; pdamp = pdamp .or. m%link_kind(j) == LINK_DASHPOT
         else
            ground = .true.; gdamp = gdamp .or. m%link_kind(j) == LINK_DASHPOT
         end if
      end do
      do j = 1, m%nchain
         ground = .true.
         if (allocated(m%chain(j)%c)) gdamp = gdamp .or. any(m%chain(j)%c > 0.0_dp)
      end do
      allocate (self%gumax(merge(n, 0, ground)), self%gvmax(merge(n, 0, gdamp)), &
                self%pumax(merge(n, 0, pair)), self%pvmax(merge(n, 0, pdamp)), stat=st)
      if (st /= 0) return
      self%gumax = 0.0_dp; self%gvmax = 0.0_dp; self%pumax = 0.0_dp; self%pvmax = 0.0_dp
   end subroutine link_peak_arrays

   !> The committed state becomes the start of the next step by swapping the buffers: the
   !> step writes every entry of u, v, a before reading it.
   subroutine chain_begin_step(self)
      class(chain_newmark_t), intent(inout) :: self
      call swap(self%u, self%un); call swap(self%v, self%vn); call swap(self%a, self%an)
   end subroutine chain_begin_step

   subroutine chain_step(self, m, t, o, stat)
      class(chain_newmark_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      real(dp), intent(in) :: t
      type(observer_t), intent(inout) :: o
      integer, intent(out) :: stat
      integer :: it, j, i
      logical :: flipped, ok
      real(dp) :: w_ext, f
      stat = MARTELLO_OK
      self%acc_n = self%acc
      self%acc = uniform_acceleration(m, t)
      self%mdu = 0.0_dp
      ok = .true.
      if (self%factored) then
         ! the first iterate: one solve with the kept factors about the committed state
         call nodal_forces(self, m, t)
         call linearised_sweep(self, m)
         o%counters(C_NEWTON) = o%counters(C_NEWTON) + 1_i8
      else
         ! no factors: the elements at u = u_n (a solve with zero factors is no increment)
         self%rp = 0.0_dp; self%fe = 0.0_dp
      end if
      call evaluate(self, m, .true., flipped)
      call nodal_forces(self, m, t)
      o%counters(C_RESIDUALS) = o%counters(C_RESIDUALS) + 1_i8
      do it = 1, MAX_FUSED
         if (.not. flipped .and. self%factored) exit
         if (it == MAX_FUSED) ok = .false.
         if (.not. ok) exit
         call refactor_sweep(self, m, o, ok)
         if (.not. ok) exit
         call evaluate(self, m, .false., flipped)
         call nodal_forces(self, m, t)
         o%counters(C_RESIDUALS) = o%counters(C_RESIDUALS) + 1_i8
         o%counters(C_NEWTON) = o%counters(C_NEWTON) + 1_i8
      end do
      if (.not. ok) then
         call general_step(self, m, t, o, stat)
         if (stat /= MARTELLO_OK) call link_peaks(self, m, o)
         return
      end if
      call commit(self)
      o%counters(C_FUSED) = o%counters(C_FUSED) + 1_i8
      ! external work, trapezoidal as external_work: the uniform load on the masses and the
      ! nodal forces (fixed nodes have Δu = 0)
      w_ext = 0.5_dp*(self%acc_n + self%acc)*self%mdu
      do j = 1, m%nforce
         i = m%force_node(j)
         f = tf_value(m%force_fn(j), self%t0)
         w_ext = w_ext + 0.5_dp*(f + self%fnod(j))*(self%u(i) - self%un(i))
      end do
      call observer_work(o, damping=self%wd, links=self%wl, contact=self%wc)
      call observer_work(o, external=w_ext)
   end subroutine chain_step

   !> fe ← f_int − the nodal forces at t (fnod: those it holds now).
   subroutine nodal_forces(self, m, t)
      class(chain_newmark_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      real(dp), intent(in) :: t
      integer :: j
      real(dp) :: f
      do j = 1, m%nforce
         f = tf_value(m%force_fn(j), t)
         self%fe(m%force_node(j)) = self%fe(m%force_node(j)) + self%fnod(j) - f
         self%fnod(j) = f
      end do
   end subroutine nodal_forces

   !> The forward sweep of the first iterate: the residual at u = u_n linearised about the
   !> committed state, r = M a₀ + f_c + C_t Δv₀ − f_ext (exact while no branch changes: the
   !> laws are affine on a branch), forward-substituted with the kept factors. a₀, Δv₀: the
   !> Newmark a and v − vₙ of u = u_n; C_t the damping tangent on the factors' branches.
   subroutine linearised_sweep(self, m)
      class(chain_newmark_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      if (self%chain_links) then
         call sweep(m%chain(1)%c)
      else
         call sweep(self%cg)
      end if
      call pin_fixed(self)
   contains
      subroutine sweep(cg)
         real(dp), intent(in), contiguous :: cg(:)
         if (.not. (self%pair_links .or. self%kelvin .or. self%others) .and. &
             self%from_chain_of_one_kind()) then
            ! the usual chain, with these as constants (back_kernel's call says why)
            call forward_kernel(self%n, self%h, self%gamma, self%c1, self%c2, self%cv, self%acc, &
                                .false., .false., .false., self%pair_contacts, .false., 0, 0, &
                                self%vn, self%an, 0, self%mass, self%fe, self%rp, cg, self%kp, &
                                self%cp, self%pk, self%pc, self%pbrf, self%xcd, self%xco, &
                                self%xjo, m%fixed)
         else
            call forward_kernel(self%n, self%h, self%gamma, self%c1, self%c2, self%cv, self%acc, &
                                self%pair_links, self%kelvin, self%others, self%pair_contacts, &
                                self%any_fixed, self%sk, self%sc, self%vn, self%an, self%sm, &
                                self%mass, self%fe, self%rp, cg, self%kp, self%cp, self%pk, &
                                self%pc, self%pbrf, self%xcd, self%xco, self%xjo, m%fixed)
         end if
      end subroutine sweep
   end subroutine linearised_sweep

   !> linearised_sweep's loop on explicit-shape arrays (no descriptors, no aliasing: the
   !> compiler keeps everything in registers but the arrays).
   subroutine forward_kernel(n, h, gm, c1, c2, cv, acc, pl, kel, oth, pcs, fx, sk, sc, vn, an, &
                             sm, mass, fe, rp, cg, kp, cp, pk, pc, brf, xcd, xco, xjo, fixed)
      integer, intent(in), value :: n, sk, sc, sm
      real(dp), intent(in), value :: h, gm, c1, c2, cv, acc
      logical, intent(in), value :: pl, kel, oth, pcs, fx
      real(dp), intent(in) :: vn(0:n), an(0:n), mass(*), rp(n), cg(n), kp(0:*), cp(0:*), &
                              pk(0:*), pc(0:*), xcd(0:*), xco(0:*), xjo(0:*)
      integer(int8), intent(in) :: brf(0:n)
      logical, intent(in) :: fixed(n)
      real(dp), intent(inout) :: fe(0:n)     !< in: the committed internal force; out: y
      integer :: i
      real(dp) :: dvm, dv0, dvp, a0, ap, cdv, cd, co, com, ym, g1, lm
      ! a₀ = −c₁vₙ − c₂aₙ and Δv₀ = v₀ − vₙ = h((1 − γ)aₙ + γa₀) of each node
      g1 = 1.0_dp - gm
      dvm = 0.0_dp; com = 0.0_dp; ym = 0.0_dp; lm = 0.0_dp
      a0 = -c1*vn(1) - c2*an(1)
      dv0 = h*(g1*an(1) + gm*a0)
      do i = 1, n
         ap = 0.0_dp; dvp = 0.0_dp
         if (i < n) then
            ap = -c1*vn(i + 1) - c2*an(i + 1)
            dvp = h*(g1*an(i + 1) + gm*ap)
         end if
         ! C_t(i, i) and C_t(i, i+1) on the factors' branches
         cd = cg(i); co = 0.0_dp
         if (pl) then
            cd = cd + cp(i - 1) + cp(i); co = -cp(i)
         end if
         if (kel) then
            if (brf(i - 1) == B_ON) cd = cd + pc((i - 1)*sc)
            if (brf(i) == B_ON) then
               cd = cd + pc(i*sc); co = co - pc(i*sc)
            end if
         end if
         if (oth) then
            cd = cd + xcd(i); co = co + xco(i)
         end if
         cdv = cd*dv0 + com*dvm + co*dvp
         ym = mass(1 + (i - 1)*sm)*(acc - a0) - fe(i) - cdv - lm*ym
         fe(i) = ym
         dvm = dv0; dv0 = dvp; a0 = ap; com = co
         ! L(i+1, i) for the next node
         if (i < n) lm = coupling(i, cv, pl, pcs, oth, fx, sk, sc, kp, cp, pk, pc, brf, xjo, &
                                  fixed)*rp(i)
      end do
      fe(0) = 0.0_dp
   end subroutine forward_kernel

   !> The forward sweep of a Newton iterate after a branch change: the tangent on the current
   !> branches, J = c_m M + K_t + c_v C_t = L D Lᵀ (reciprocal pivots; fixed rows and columns
   !> the identity's), and the residual r = M a + f_int − f_ext forward-substituted.
   !> ok = .false. on a pivot that is not > 0.
   subroutine refactor_sweep(self, m, o, ok)
      class(chain_newmark_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      type(observer_t), intent(inout) :: o
      logical, intent(out) :: ok
      if (self%others) call others_tangent(self, m)
      self%pbrf = self%pbr; self%bbrf = self%bbr; self%xbrf = self%xbr
      o%counters(C_JACOBIANS) = o%counters(C_JACOBIANS) + 1_i8
      o%counters(C_FACTORIZATIONS) = o%counters(C_FACTORIZATIONS) + 1_i8
      if (self%chain_links) then
         call sweep(m%chain(1)%k, m%chain(1)%c)
      else
         call sweep(self%kg, self%cg)
      end if
      self%factored = ok
   contains
      subroutine sweep(kg, cg)
         real(dp), intent(in), contiguous :: kg(:), cg(:)
         call refactor_kernel(self%n, self%cm, self%cv, self%acc, self%pair_links, &
                              self%pair_contacts, self%others, self%sk, self%sc, self%a, self%sm, &
                              self%mass, m%fixed, self%fe, kg, cg, self%kp, self%cp, self%pk, &
                              self%pc, self%pbr, self%xjd, self%xjo, self%rp, ok)
      end subroutine sweep
   end subroutine refactor_sweep

   !> refactor_sweep's loop on explicit-shape arrays.
   subroutine refactor_kernel(n, cm, cv, acc, pl, pcs, oth, sk, sc, a, sm, mass, fixed, fe, kg, &
                              cg, kp, cp, pk, pc, br, xjd, xjo, rp, ok)
      integer, intent(in) :: n, sk, sc, sm
      real(dp), intent(in) :: cm, cv, acc
      logical, intent(in) :: pl, pcs, oth, fixed(n)
      real(dp), intent(in) :: a(0:n), mass(*), kg(n), cg(n), kp(0:*), cp(0:*), pk(0:*), pc(0:*), &
                              xjd(0:*), xjo(0:*)
      real(dp), intent(inout) :: fe(0:n)     !< in: the internal force at the iterate; out: y
      integer(int8), intent(in) :: br(0:n)
      real(dp), intent(out) :: rp(n)
      logical, intent(out) :: ok
      integer :: i
      real(dp) :: p, jd, jo, jom, tp, tpm, ym, gm
      ok = .true.
      tpm = 0.0_dp; gm = 0.0_dp; ym = 0.0_dp; jom = 0.0_dp
      do i = 1, n
         ! tp: the tangent of pair (i, i+1), K_t + c_v C_t
         tp = 0.0_dp
         if (i < n) then
            if (pl) tp = kp(i) + cv*cp(i)
            if (pcs) then
               if (br(i) == B_ON) tp = tp + (pk(i*sk) + cv*pc(i*sc))
            end if
         end if
         jd = kg(i) + cv*cg(i) + tpm + tp
         if (oth) jd = jd + xjd(i)
         ! J(i, i+1) as the sweeps compute it again (coupling)
         jo = 0.0_dp
         if (i < n) jo = coupling(i, cv, pl, pcs, oth, .true., sk, sc, kp, cp, pk, pc, br, xjo, fixed)
         if (fixed(i)) then
            p = 1.0_dp
         else
            p = cm*mass(1 + (i - 1)*sm) + jd - jom*gm
         end if
         if (.not. (p > 0.0_dp)) ok = .false.
         rp(i) = 1.0_dp/p
         if (fixed(i)) then
            ym = 0.0_dp
         else
            ym = mass(1 + (i - 1)*sm)*(acc - a(i)) - fe(i) - gm*ym
         end if
         gm = jo*rp(i)
         fe(i) = ym
         tpm = tp; jom = jo
      end do
      fe(0) = 0.0_dp
   end subroutine refactor_kernel

   !> J(i, i+1), i < n, of the factors made on the branches brf: −(K_t + c_v C_t) of the pair
   !> (i, i+1) (its summed links, its contact where on), plus the other elements' (xjo), 0 at
   !> a fixed row or column (fx: some node is fixed). L(i+1, i) = J(i, i+1)·rp(i): the sweeps
   !> compute it again from the branch bytes rather than read it from an array (8 B per node
   !> less to keep, and to stream at every step), to the same bits as the factorisation.
   pure real(dp) function coupling(i, cv, pl, pcs, oth, fx, sk, sc, kp, cp, pk, pc, brf, xjo, &
                                   fixed) result(jo)
      integer, intent(in) :: i, sk, sc
      real(dp), intent(in) :: cv, kp(0:*), cp(0:*), pk(0:*), pc(0:*), xjo(0:*)
      logical, intent(in) :: pl, pcs, oth, fx, fixed(*)
      integer(int8), intent(in) :: brf(0:*)
      real(dp) :: tp
      tp = 0.0_dp
      if (pl) tp = kp(i) + cv*cp(i)
      if (pcs) then
         if (brf(i) == B_ON) tp = tp + (pk(i*sk) + cv*pc(i*sc))
      end if
      jo = -tp
      if (oth) jo = jo + xjo(i)
      if (fx) then
         if (fixed(i) .or. fixed(i + 1)) jo = 0.0_dp
      end if
   end function coupling

   !> Fixed rows carry no residual: their Δu is 0 (their column of the factors is 0, so no
   !> other row depends on their entry of y).
   subroutine pin_fixed(self)
      class(chain_newmark_t), intent(inout) :: self
      integer :: k
      do k = 1, size(self%fixed_nodes)
         self%fe(self%fixed_nodes(k)) = 0.0_dp
      end do
   end subroutine pin_fixed

   !> The backward sweep and the elements at the new iterate: Δu = D⁻¹y − Lᵀ Δu, and u, v, a
   !> by the Newmark relations (Δa = c_m Δu, Δv = c_v Δu; from_start: from u = u_n, a₀, v₀,
   !> else from the current iterate); as each node and pair is known, its linear links and
   !> pair contact: the nodal internal force fe, each pair contact's branch, and the
   !> trapezoidal works of the step were it to end here, as mech_commit sums them
   !> (½(f_n + f)·Δ, f_n from the committed state); then the other elements (others).
   !> flipped: a branch differs from the factors'. Σ m_i Δu_i for the external work.
   subroutine evaluate(self, m, from_start, flipped)
      class(chain_newmark_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      logical, intent(in) :: from_start
      logical, intent(out) :: flipped
      real(dp) :: mdu
      if (self%chain_links) then
         call sweep(m%chain(1)%k, m%chain(1)%c)
      else
         call sweep(self%kg, self%cg)
      end if
      self%mdu = self%mdu + mdu
      if (self%others) call others(self, m, flipped)
      self%fnod = 0.0_dp
   contains
      subroutine sweep(kg, cg)
         real(dp), intent(in), contiguous :: kg(:), cg(:)
         if (.not. (self%pair_links .or. self%kelvin) .and. self%pair_contacts .and. &
             self%from_chain_of_one_kind()) then
            ! the usual chain (springs and dashpots to ground, one linear contact law and gap
            ! for every pair, one mass): the same kernel with these as constants, which the
            ! compiler specialises (no branches on them, the parameters read once)
            call back_kernel(self%n, from_start, .false., .true., .false., .false., .false., 0, 0, &
                             0, 0, 0, self%cm, self%cv, self%c1, self%c2, self%h, self%gamma, &
                             self%rp, self%u, self%v, self%a, self%un, self%vn, self%an, 0, &
                             self%mass, self%fe, kg, cg, self%kp, self%cp, self%psgn, self%pgap, &
                             self%pk, self%pc, self%plaw, self%pbr, self%pbrc, self%pbrf, &
                             self%xjo, m%fixed, mdu, self%wd, self%wl, self%wc, flipped)
         else
            call back_kernel(self%n, from_start, self%pair_links, self%pair_contacts, self%kelvin, &
                             self%others, self%any_fixed, self%ss, self%sg, self%sk, self%sc, &
                             self%sl, self%cm, self%cv, self%c1, self%c2, self%h, self%gamma, &
                             self%rp, self%u, self%v, self%a, self%un, self%vn, self%an, self%sm, &
                             self%mass, self%fe, kg, cg, self%kp, self%cp, self%psgn, self%pgap, &
                             self%pk, self%pc, self%plaw, self%pbr, self%pbrc, self%pbrf, &
                             self%xjo, m%fixed, mdu, self%wd, self%wl, self%wc, flipped)
         end if
      end subroutine sweep
   end subroutine evaluate

   !> evaluate's sweep on explicit-shape arrays (no descriptors, no aliasing). The parameter
   !> arrays of the pair contacts are read at i·stride (stride 0: one value for the chain).
   subroutine back_kernel(n, from_start, pl, pcs, kel, oth, fx, ss, sg, sk, sc, sl, cm, cv, c1, &
                          c2, h, gm, rp, u, v, a, un, vn, an, sm, mass, fe, kg, cg, kp, cp, psgn, &
                          pgap, pk, pc, plaw, pbr, pbrc, pbrf, xjo, fixed, mdu, wd, wl, wc, flip)
      integer, intent(in), value :: n, ss, sg, sk, sc, sl, sm
      logical, intent(in), value :: from_start, pl, pcs, kel, oth, fx
      real(dp), intent(in), value :: cm, cv, c1, c2, h, gm
      real(dp), intent(in) :: rp(n), un(0:n), vn(0:n), an(0:n), mass(*), kg(n), &
                              cg(n), kp(0:*), cp(0:*), psgn(0:*), pgap(0:*), pk(0:*), pc(0:*), &
                              xjo(0:*)
      logical, intent(in) :: fixed(n)
      integer(int8), intent(in) :: plaw(0:*), pbrc(0:n), pbrf(0:n)
      real(dp), intent(inout) :: u(0:n), v(0:n), a(0:n)
      real(dp), intent(inout) :: fe(0:n)     !< in: y; out: the internal force
      integer(int8), intent(inout) :: pbr(0:n)
      real(dp), intent(out) :: mdu, wd, wl, wc
      logical, intent(out) :: flip
      integer :: i
      integer(int8) :: br, law
      real(dp) :: x, ui, vi, ai, uni, vni, u1, v1, un1, vn1, fi, f1, du, dun, fp, s, pen, penn, &
                  f, fn, gp, g1, k, c, hd, lx
      g1 = 1.0_dp - gm
      mdu = 0.0_dp; wd = 0.0_dp; wl = 0.0_dp; wc = 0.0_dp; flip = .false.
      x = 0.0_dp; u1 = 0.0_dp; v1 = 0.0_dp; un1 = 0.0_dp; vn1 = 0.0_dp; f1 = 0.0_dp
      do i = n, 1, -1
         ! Δu(i) = D⁻¹y(i) − L(i+1, i)·Δu(i+1)
         lx = 0.0_dp
         if (i < n) lx = coupling(i, cv, pl, pcs, oth, fx, sk, sc, kp, cp, pk, pc, pbrf, xjo, &
                                  fixed)*rp(i)*x
         x = rp(i)*fe(i) - lx
         uni = un(i); vni = vn(i)
         if (from_start) then
            ! the Newmark a₀, v₀ of u = uₙ, as the general path's kinematics associate them
            ai = -c1*vni - c2*an(i)
            vi = vni + h*(g1*an(i) + gm*ai) + cv*x
            ai = ai + cm*x
            ui = uni + x
         else
            ui = u(i) + x; vi = v(i) + cv*x; ai = a(i) + cm*x
         end if
         u(i) = ui; v(i) = vi; a(i) = ai
         mdu = mdu + mass(1 + (i - 1)*sm)*x
         ! the links of node i to ground
         k = kg(i); c = cg(i); hd = 0.5_dp*(ui - uni)
         fi = k*ui + c*vi
         wl = wl + k*(uni + ui)*hd
         wd = wd + c*(vni + vi)*hd
         if (i < n) then
            ! the pair (i, i+1): node i+1 is known
            du = ui - u1; dun = uni - un1
            if (pl) then
               fp = kp(i)*du + cp(i)*(vi - v1)
               wl = wl + 0.5_dp*kp(i)*(dun + du)*(du - dun)
               wd = wd + 0.5_dp*cp(i)*((vni - vn1) + (vi - v1))*(du - dun)
               fi = fi + fp; f1 = f1 - fp
            end if
            if (pcs) then
               ! linear or Kelvin (Anagnostopoulos 1988), as martello_contact_laws
               s = psgn(i*ss); gp = pgap(i*sg)
               pen = s*du - gp; penn = s*dun - gp
               br = B_OFF; f = 0.0_dp
               if (pen > 0.0_dp) then
                  br = B_ON; f = pk(i*sk)*pen
                  if (kel) then
                     law = plaw(i*sl)
                     if (law /= K_LINEAR) then
                        f = f + pc(i*sc)*(s*(vi - v1))
                        if (law == K_KELVIN_CLIPPED .and. f <= 0.0_dp) then
                           f = 0.0_dp; br = B_CLIPPED
                        end if
                     end if
                  end if
               end if
               pbr(i) = br
               if (br /= pbrf(i)) flip = .true.
               fn = 0.0_dp
               if (pbrc(i) == B_ON) then
                  fn = pk(i*sk)*penn
                  if (kel) fn = fn + pc(i*sc)*(s*(vni - vn1))
               end if
               wc = wc + 0.5_dp*(fn + f)*(pen - penn)
               fi = fi + s*f; f1 = f1 - s*f
            end if
            fe(i + 1) = f1
         end if
         f1 = fi
         u1 = ui; v1 = vi; un1 = uni; vn1 = vni
      end do
      fe(1) = f1
      fe(0) = 0.0_dp
   end subroutine back_kernel

   !> The bilinear links and the other contacts at the iterate, one by one (after the sweep:
   !> fe holds the rest): forces into fe, branches, works.
   subroutine others(self, m, flipped)
      class(chain_newmark_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      logical, intent(inout) :: flipped
      integer :: idx, j, a, b
      real(dp) :: du, f, kt, pen, penn, fn
      logical :: yielding
      integer(int8) :: br
      associate (u => self%u, v => self%v, un => self%un, vn => self%vn, fe => self%fe, &
                 par => m%link_par)
         do idx = 1, size(self%bl)
            ! the return map from the committed state
            j = self%bl(idx); a = m%link_a(j); b = m%link_b(j)
            du = u(a) - u(b)
            call bilinear_return_map(par(L_STIFF, j), par(L_YIELD, j), par(L_HARDENING, j), &
                                     self%bfc(idx), self%bdu(idx), du, f, kt, yielding)
            br = B_ELASTIC
            if (yielding) br = merge(B_UPPER, B_LOWER, f > par(L_HARDENING, j)*par(L_STIFF, j)*du)
            self%bbr(idx) = br
            flipped = flipped .or. br /= self%bbrf(idx)
            self%wl = self%wl + 0.5_dp*(self%bfc(idx) + f)*(du - self%bdu(idx))
            self%bft(idx) = f; self%bdut(idx) = du
            fe(a) = fe(a) + f; fe(b) = fe(b) - f
         end do
         do idx = 1, size(self%xg)
            j = self%xg(idx); a = m%con_a(j); b = m%con_b(j)
            pen = u(a) - u(b) - m%con_gap(j)
            call contact_law(m, j, pen, v(a) - v(b), br, f)
            self%xbr(idx) = br
            flipped = flipped .or. br /= self%xbrf(idx)
            penn = un(a) - un(b) - m%con_gap(j)
            call contact_law(m, j, penn, vn(a) - vn(b), br, fn, self%xbrc(idx))
            self%wc = self%wc + 0.5_dp*(fn + f)*(pen - penn)
            fe(a) = fe(a) + f; fe(b) = fe(b) - f
         end do
         fe(0) = 0.0_dp
      end associate
   end subroutine others

   !> Contact j's force f at δ = pen, δ̇ = rate and its branch br: on its whole law, or on
   !> the given branch on (the committed one).
   subroutine contact_law(m, j, pen, rate, br, f, on)
      type(model_t), intent(in) :: m
      integer, intent(in) :: j
      real(dp), intent(in) :: pen, rate
      integer(int8), intent(out) :: br
      real(dp), intent(out) :: f
      integer(int8), intent(in), optional :: on
      br = B_OFF; f = 0.0_dp
      if (present(on)) then
         if (on /= B_ON) return
      else if (.not. (pen > 0.0_dp)) then
         return
      end if
      br = B_ON
      f = m%con_par(P_STIFF, j)*pen
      if (m%con_law(j) == LAW_KELVIN) then
         f = f + m%con_par(P_DAMPING, j)*rate
         if (.not. present(on) .and. m%con_par(P_CLIP, j) > 0.5_dp .and. f <= 0.0_dp) then
            f = 0.0_dp; br = B_CLIPPED
         end if
      end if
   end subroutine contact_law

   !> The other elements' tangents on their current branches, per node: xjd, xjo of
   !> K_t + c_v C_t and C_t alone in xcd, xco (what the factors are made with).
   subroutine others_tangent(self, m)
      class(chain_newmark_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      integer :: idx, j
      real(dp) :: k, c
      self%xjd = 0.0_dp; self%xjo = 0.0_dp; self%xcd = 0.0_dp; self%xco = 0.0_dp
      do idx = 1, size(self%bl)
         j = self%bl(idx)
         k = m%link_par(L_STIFF, j)
         if (self%bbr(idx) /= B_ELASTIC) k = m%link_par(L_HARDENING, j)*k
         call stencil(m%link_a(j), m%link_b(j), k, 0.0_dp)
      end do
      do idx = 1, size(self%xg)
         j = self%xg(idx)
         if (self%xbr(idx) /= B_ON) cycle
         c = 0.0_dp
         if (m%con_law(j) == LAW_KELVIN) c = m%con_par(P_DAMPING, j)
         call stencil(m%con_a(j), m%con_b(j), m%con_par(P_STIFF, j), c)
      end do
      self%xjd(0) = 0.0_dp; self%xcd(0) = 0.0_dp
   contains
      !> J += k + c_v c, C_t += c on the two-node stencil of (i, l): |i − l| ≤ 1 or one end
      !> on ground (0).
      subroutine stencil(i, l, k, c)
         integer, intent(in) :: i, l
         real(dp), intent(in) :: k, c
         real(dp) :: val
         val = k + self%cv*c
         self%xjd(i) = self%xjd(i) + val; self%xjd(l) = self%xjd(l) + val
         self%xcd(i) = self%xcd(i) + c; self%xcd(l) = self%xcd(l) + c
         if (i > 0 .and. l > 0) then
            self%xjo(min(i, l)) = self%xjo(min(i, l)) - val
            self%xco(min(i, l)) = self%xco(min(i, l)) - c
         end if
      end subroutine stencil
   end subroutine others_tangent

   !> Accept the last evaluation: committed ← trial (branches, bilinear states).
   subroutine commit(self)
      class(chain_newmark_t), intent(inout) :: self
      call swap_int8(self%pbr, self%pbrc); call swap_int8(self%xbr, self%xbrc)
      call swap(self%bfc, self%bft); call swap(self%bdu, self%bdut)
   end subroutine commit

   !> A step the fused sweeps do not settle, taken by the general path from the same
   !> committed state (its chatter rule, line search and failure messages). Its stepper is
   !> made at the first such step (on the model with its chains as links and contacts one by
   !> one: their numbers are those of all the model's items) and handed the committed state
   !> each time: the element states from ours (a contact we hold open has no force), f_ext at
   !> t_n.
   subroutine general_step(self, m, t, o, stat)
      class(chain_newmark_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      real(dp), intent(in) :: t
      type(observer_t), intent(inout) :: o
      integer, intent(out) :: stat
      self%factored = .false.
      if (m%nchain > 0) then
         if (.not. allocated(self%gm)) then
            allocate (self%gm, source=m, stat=stat)
            if (stat /= 0) then
               call out_of_memory('a copy of the model for the general path of the fused chain step', &
                                  -1.0_dp, FIX_SMALLER_SCENE, stat, o%message)
            else
               call model_expand_chains(self%gm, stat, o%message)
            end if
            if (stat /= MARTELLO_OK) then
               call observer_failed(o, t, stat); return
            end if
            call effective_mass_prepare(self%gm, o%message, stat)
            if (stat /= MARTELLO_OK) return
         end if
         call take(self%gm)
      else
         call take(m)
      end if
   contains
      subroutine take(gm)
         type(model_t), intent(in) :: gm
         integer(i8) :: saved(size(o%counters))
         integer :: idx, j, i
         if (.not. allocated(self%gen)) then
            ! its start at t = 0 (a = M⁻¹(f_ext − f_int)) is overwritten below: not counted
            allocate (self%gen, stat=stat)
            if (stat /= 0) then
               call out_of_memory('the general path of the fused chain step', -1.0_dp, &
                                  FIX_SMALLER_SCENE, stat, o%message)
               call observer_failed(o, t, stat); return
            end if
            saved = o%counters
            call self%gen%init(gm, self%settings, o, stat)
            o%counters = saved
            if (stat /= MARTELLO_OK) return
         end if
         associate (gen => self%gen, ms => self%gen%ms)
            gen%un = self%un; gen%vn = self%vn; gen%an = self%an; gen%t0 = self%t0
            do idx = 1, size(self%blo)
               j = self%blo(idx)
               ms%link_fc(j) = self%bfc(idx); ms%link_u(j) = self%bdu(idx)
            end do
            ms%forced_off = .false.
            call internal_forces(gm, ms, gen%un, gen%vn, gen%fint)
            call mech_commit(gm, ms, gen%un)
            do i = 1, m%n - 1
               if (pair_contact(self, i) > 0) call hold(pair_contact(self, i), self%pbrc(i))
            end do
            do idx = 1, size(self%xc)
               call hold(self%xc(idx), self%xbrc(idx))
            end do
            call external_forces(gm, gen%mrow, self%t0, gen%fext)
            gen%tangent_valid = .false.
            call gen%step(gm, t, o, stat)
            if (stat /= MARTELLO_OK) return
            self%u = gen%u; self%v = gen%v; self%a = gen%a
            do idx = 1, size(self%blo)
               j = self%blo(idx)
               self%bfc(idx) = ms%link_fc(j); self%bdu(idx) = ms%link_u(j)
            end do
            do i = 1, m%n - 1
               if (pair_contact(self, i) > 0) self%pbrc(i) = branch_of(pair_contact(self, i))
            end do
            do idx = 1, size(self%xc)
               self%xbrc(idx) = branch_of(self%xc(idx))
            end do
         end associate
      end subroutine take

      !> contact j committed off here is off there (no force)
      subroutine hold(j, br)
         integer, intent(in) :: j
         integer(int8), intent(in) :: br
         if (br /= B_OFF) return
         self%gen%ms%con_on(j) = .false.; self%gen%ms%con_f(j) = 0.0_dp
      end subroutine hold

      !> our branch of contact j from the general path's committed state: clipped where the
      !> Kelvin law's cut-off holds its force at 0
      integer(int8) function branch_of(j) result(br)
         integer, intent(in) :: j
         integer :: a, b, scheme, law
         real(dp) :: gap, par(NPAR_CONTACT)
         br = B_OFF
         if (.not. self%gen%ms%con_on(j)) return
         br = B_ON
         call model_contact_at(m, j, a, b, gap, scheme, law, par)
         if (law == LAW_KELVIN .and. par(P_CLIP) > 0.5_dp .and. self%gen%ms%con_f(j) == 0.0_dp) &
            br = B_CLIPPED
      end function branch_of
   end subroutine general_step

   !> The observer's start: the phases of the contacts closed at t = 0 and the energies
   !> there.
   subroutine chain_measure_start(self, m, o, energy_interval, stat)
      class(chain_newmark_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      type(observer_t), intent(inout) :: o
      integer, intent(in) :: energy_interval
      integer, intent(out) :: stat
      integer :: i, idx, j
      do i = 1, self%n - 1
         if (pair_contact(self, i) == 0 .or. self%pbrc(i) == B_OFF) cycle
         call observer_open_phase(o, pair_contact(self, i), 0.0_dp, &
                                  self%psgn(i*self%ss)*(self%v(i) - self%v(i + 1)))
      end do
      do idx = 1, size(self%xg)
         j = self%xg(idx)
         if (self%xbrc(idx) /= B_OFF) call observer_open_phase(o, self%xc(idx), 0.0_dp, &
                                                               self%v(m%con_a(j)) - self%v(m%con_b(j)))
      end do
      call observer_begin(o, m, self%ms, self%u, self%v, self%a, energy_interval, self%advice, &
                          0.0_dp, stat, energies=energies(self, m))
      if (stat /= MARTELLO_OK) call observer_failed(o, 0.0_dp, stat)
   end subroutine chain_measure_start

   !> The committed state at t = t_k measured item by item: every node's peaks, every
   !> contact's phases and maxima, the link maxima, each with its extrema inside the step
   !> located as the general path locates them (observer_node_peaks, observer_a_parabolas,
   !> observer_contact_step_peaks, observer_link_step_extremum; docs/results.md); then the
   !> observer's sample (energies where due, the history row, the divergence test). At a
   !> recorded sample (and on a failure) the link peaks are handed over.
   subroutine chain_measure(self, m, o, t, k, stat)
      class(chain_newmark_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      type(observer_t), intent(inout) :: o
      real(dp), intent(in) :: t
      integer(i8), intent(in) :: k
      integer, intent(out) :: stat
      real(dp) :: h
      ! unallocated: not present (the history records no link, the energies are not due)
      real(dp), allocatable :: pen(:), force(:), lf(:), ld(:), e(:)
      logical :: rec
      h = merge(self%h, 0.0_dp, k > 0)
      call measure_nodes(self, m, o, t, h)
      call measure_others(self, m, o, t, h)
      rec = observer_recorded(o, k)
      allocate (pen(0), force(0), stat=stat)
      if (stat == 0 .and. rec .and. size(o%out_contacts) > 0) &
         call contact_states(self, m, o%out_contacts, pen, force, stat)
      if (rec) call link_peaks(self, m, o)
      if (stat == 0 .and. rec .and. size(o%out_links) > 0) call link_states(self, m, o%out_links, lf, ld, stat)
      if (stat /= 0) then
         call out_of_memory('the recorded contact and link states of the fused chain step', &
                            REAL_BYTES*2*(model_ncontacts(m) + real(model_nlinks(m), dp)), &
                            FIX_SMALLER_SCENE, stat, o%message)
         call observer_failed(o, t, stat); return
      end if
      if (observer_energy_due(o, k)) e = energies(self, m)
      call observer_sample(o, m, self%ms, t, self%u, self%v, self%a, pen, force, k, stat, lf, ld, &
                           folded=.true., energies=e)
      if (stat /= MARTELLO_OK) call link_peaks(self, m, o)
   end subroutine chain_measure

   !> The nodes and pairs in one pass: node peaks (observer_node_peaks, the candidates of the
   !> located |a|), the link maxima, and each pair contact's phases and maxima
   !> (observer_contact_step_peaks, observer_phase_change, observer_contact_peaks) from its
   !> committed branch: δ, δ̇, δ̈ at both ends of the step locate an onset or a separation.
   !> h: the step (0 at t = 0); the located extrema are on the step from the previous sample.
   subroutine measure_nodes(self, m, o, t, h)
      class(chain_newmark_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      type(observer_t), intent(inout) :: o
      real(dp), intent(in) :: t, h
      logical :: located
      ! the method's steps are smooth (run_fixed_step: o%smooth_steps), so its peaks inside
      ! them are located once a previous sample exists
      located = o%smooth_steps .and. o%prev_t >= 0.0_dp .and. t > o%prev_t
      ! the candidates of |a| decided (or completed) with this sample's a, before its own
      if (located .and. tracks(o, TRACK_NODE_PEAKS)) &
         call observer_a_parabolas(o, m, t, self%a(1:self%n), o%nsamples + 1)
      if (.not. self%kelvin .and. self%pair_contacts .and. self%from_chain_of_one_kind() .and. &
          o%fixed_steps .and. o%tracking == TRACK_ALL .and. &
          size(self%pumax) == 0 .and. size(self%pvmax) == 0) then
         ! the usual chain, every result tracked, with these as constants (back_kernel's call
         ! says why)
         call measure_kernel(self%n, t, h, o%prev_t, .true., located, .true., .true., .true., &
                             size(self%gumax) > 0, size(self%gvmax) > 0, .false., .false., .true., &
                             .false., 0, 0, 0, 0, 0, self%u, self%v, self%a, self%un, self%vn, &
                             self%an, self%psgn, self%pgap, self%pk, self%pc, self%plaw, &
                             self%pbrc, self%pc0, self%pcon, o%u_max, o%u_min, o%v_absmax, &
                             o%a_absmax, o%u_absmax, o%t_absmax, o%u_peak, o%t_peak, self%gumax, &
                             self%gvmax, self%pumax, self%pvmax, o%pen_max, o%force_max, o)
      else
         call measure_kernel(self%n, t, h, o%prev_t, o%fixed_steps, located, &
                             tracks(o, TRACK_NODE_PEAKS), tracks(o, TRACK_CONTACT_PEAKS), &
                             tracks(o, TRACK_PHASES), size(self%gumax) > 0, size(self%gvmax) > 0, &
                             size(self%pumax) > 0, size(self%pvmax) > 0, self%pair_contacts, &
                             self%kelvin, self%ss, self%sg, self%sk, self%sc, self%sl, self%u, &
                             self%v, self%a, self%un, self%vn, self%an, self%psgn, self%pgap, &
                             self%pk, self%pc, self%plaw, self%pbrc, self%pc0, self%pcon, o%u_max, &
                             o%u_min, o%v_absmax, o%a_absmax, o%u_absmax, o%t_absmax, o%u_peak, &
                             o%t_peak, self%gumax, self%gvmax, self%pumax, self%pvmax, o%pen_max, &
                             o%force_max, o)
      end if
   end subroutine measure_nodes

   !> measure_nodes' loop on explicit-shape arrays. The observer's per-node and per-contact
   !> maxima come in as arrays (observer_node_peaks, observer_contact_peaks); o itself is
   !> touched only where a node raises its |a| (a candidate), a contact in contact over the
   !> step is located, a phase opens or closes, and for the open-phase maxima (none of these
   !> reads or writes the arrays passed apart). nodes, contacts, phases: what the run tracks;
   !> located: the extrema inside the step from t_prev (the general path's: the nodes'
   !> hermite_extremum and parabola of |a|, a link's elongation on the cubic Hermite of
   !> (du, du̇) and a dashpot's rate on that of (du̇, dü), the contacts' δ and force).
   subroutine measure_kernel(n, t, h, t_prev, fixed_steps, located, nodes, contacts, phases, &
                             gu, gv, pu, pv, pcs, kel, &
                             ss, sg, sk, sc, sl, u, v, a, un, vn, an, psgn, pgap, pk, pc, plaw, &
                             br, pc0, pcon, umax, umin, vmax, amax, uabs, tabs, upk, tpk, gumax, &
                             gvmax, pumax, pvmax, pen_max, force_max, o)
      integer, intent(in), value :: n, ss, sg, sk, sc, sl
      real(dp), intent(in), value :: t, h, t_prev
      logical, intent(in), value :: fixed_steps, located, nodes, contacts, phases, gu, gv, pu, &
                                    pv, pcs, kel
      real(dp), intent(in) :: u(0:n), v(0:n), a(0:n), un(0:n), vn(0:n), an(0:n), psgn(0:*), &
                              pgap(0:*), pk(0:*), pc(0:*)
      integer(int8), intent(in) :: plaw(0:*), br(0:n)
      integer, intent(in), value :: pc0
      integer, intent(in) :: pcon(0:*)
      real(dp), intent(inout) :: umax(*), umin(*), vmax(*), amax(*), uabs(*), tabs(*), upk(*), &
                                 tpk(*), gumax(*), gvmax(*), pumax(*), pvmax(*), pen_max(*), &
                                 force_max(*)
      type(observer_t), intent(inout) :: o
      integer :: i, p, c
      integer(i8) :: sample
      real(dp) :: s, gp, pen, f, d0, r0, q0, r1, q1, tt, tp, hh, hl, x, du, dv, dvn, f0, &
                  fr0, fr1, kp, cp
      logical :: on, fs, loc, step, raised, was, turns
      ! the scalars as locals: o, which a phase change writes, holds t_prev (the compiler
      ! would read it again after every call)
      tt = t; tp = t_prev; hh = h; fs = fixed_steps; loc = located; step = h > 0.0_dp
      hl = t - t_prev                    ! the step the extrema are located on
      sample = o%nsamples + 1            ! this sample's number (observer_sample counts it)
      do i = 1, n
         ! the node's v or a changes sign in the step (rare): its extrema inside it (read
         ! only where a node's peaks are tracked: vn, an are not read for nothing)
         turns = .false.
         if (loc .and. (nodes .or. gu .or. gv)) turns = observer_node_turns(vn(i), an(i), v(i), a(i))
         if (nodes) then
            ! observer_node_peaks in its parts: the samples' in line, the extrema inside the
            ! step where the node turns (fs: a fixed step, as loc)
            call observer_node_samples(tt, u(i), v(i), a(i), umax(i), umin(i), vmax(i), amax(i), &
                                       uabs(i), tabs(i), raised)
            if (turns .and. fs) call observer_node_step_extrema(tt, tp, un(i), vn(i), an(i), u(i), &
                                                                v(i), a(i), umax(i), umin(i), &
                                                                vmax(i), uabs(i), tabs(i), upk(i), &
                                                                tpk(i))
            if (raised .and. loc) call observer_a_candidate(o, i, an(i), a(i), sample)
         end if
         ! the maxima stored only when they change (read, not rewritten, at every step)
         if (gu) then
            x = abs(u(i))
            if (turns) then
               if (vn(i)*v(i) < 0.0_dp) x = max(x, observer_step_absmax(hl, un(i), vn(i), u(i), v(i)))
            end if
            if (x > gumax(i)) gumax(i) = x
         end if
         if (gv) then
            x = abs(v(i))
            if (turns) then
               if (an(i)*a(i) < 0.0_dp) x = max(x, observer_step_absmax(hl, vn(i), an(i), v(i), a(i)))
            end if
            if (x > gvmax(i)) gvmax(i) = x
         end if
         if (i == 1) cycle
         ! the pair (i − 1, i)
         p = i - 1
         if (pu) then
            du = u(p) - u(i); dv = v(p) - v(i); dvn = vn(p) - vn(i)
            x = abs(du)
            if (loc .and. dvn*dv < 0.0_dp) x = max(x, observer_step_absmax(hl, un(p) - un(i), dvn, &
                                                                          du, dv))
            if (x > pumax(p)) pumax(p) = x
         end if
         if (pv) then
            dv = v(p) - v(i); dvn = vn(p) - vn(i)
            x = abs(dv)
            if (loc .and. (an(p) - an(i))*(a(p) - a(i)) < 0.0_dp) &
               x = max(x, observer_step_absmax(hl, dvn, an(p) - an(i), dv, a(p) - a(i)))
            if (x > pvmax(p)) pvmax(p) = x
         end if
      end do
      if (.not. pcs) return
      ! the pair contacts, in a loop of their own (fewer arrays at a time: no registers spilt)
      do p = 1, n - 1
         i = p + 1
         if (pc0 >= 0) then
            c = pc0 + p
         else
            c = pcon(p)
            if (c == 0) cycle
         end if
         s = psgn(p*ss); gp = pgap(p*sg)
         pen = s*(u(p) - u(i)) - gp
         f = 0.0_dp
         kp = pk(p*sk); cp = 0.0_dp
         if (kel) then
            if (plaw(p*sl) /= K_LINEAR) cp = pc(p*sc)
         end if
         if (br(p) == B_ON) then
            f = kp*pen
            if (kel) then
               if (plaw(p*sl) /= K_LINEAR) f = f + cp*(s*(v(p) - v(i)))
            end if
         end if
         on = br(p) /= B_OFF
         was = o%ph_open(c)
         if (on .and. was .and. loc .and. (contacts .or. phases)) then
            ! a phase over the whole step (open before this step's change and still): its
            ! maxima inside the step; the force and its rate at the start as the previous
            ! sample had them (the law at the committed state there)
            d0 = s*(un(p) - un(i)) - gp
            if (d0 > 0.0_dp .and. pen > 0.0_dp) then
               r0 = s*(vn(p) - vn(i)); q0 = s*(an(p) - an(i))
               r1 = s*(v(p) - v(i)); q1 = s*(a(p) - a(i))
               f0 = kp*d0
               if (kel) then
                  if (plaw(p*sl) /= K_LINEAR) f0 = f0 + cp*r0
                  if (plaw(p*sl) == K_KELVIN_CLIPPED .and. f0 <= 0.0_dp) f0 = 0.0_dp
               end if
               fr0 = 0.0_dp; fr1 = 0.0_dp
               if (f0 > 0.0_dp) fr0 = kp*r0 + cp*q0
               if (f > 0.0_dp) fr1 = kp*r1 + cp*q1
               call observer_contact_step_peaks(o, c, .true., hl, d0, r0, f0, fr0, pen, r1, f, fr1)
            end if
         end if
         if (step .and. (on .neqv. was)) then
            d0 = s*(un(p) - un(i)) - gp; r0 = s*(vn(p) - vn(i)); q0 = s*(an(p) - an(i))
            r1 = s*(v(p) - v(i)); q1 = s*(a(p) - a(i))
            call observer_phase_change(o, c, on, pen, f, d0, r0, q0, pen, r1, q1, tt, hh, [p, i])
         end if
         ! the phase is open now where the contact is (a step's change, or at t = 0 the start's)
         if (phases) call observer_phase_peaks(on, pen, f, o%ph_pen(c), o%ph_f(c))
         if (contacts) call observer_contact_peaks(pen, f, pen_max(c), force_max(c))
      end do
   end subroutine measure_kernel

   !> The other elements' measurements: contacts as the pair contacts, bilinear link peaks
   !> (at the committed state and inside the step, observer_link_step_extremum).
   subroutine measure_others(self, m, o, t, h)
      class(chain_newmark_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      type(observer_t), intent(inout) :: o
      real(dp), intent(in) :: t, h
      integer :: idx, j, a, b, c, l
      real(dp) :: pen, f, r1, d0, r0, f0, fr0, fr1, hl, kc, cc
      integer(int8) :: br, br0
      logical :: located
      located = o%smooth_steps .and. o%prev_t >= 0.0_dp .and. t > o%prev_t
      hl = t - o%prev_t
      associate (u => self%u, v => self%v, acc => self%a, un => self%un, vn => self%vn, &
                 an => self%an, gap => m%con_gap)
         do idx = 1, size(self%xg)
            j = self%xg(idx); a = m%con_a(j); b = m%con_b(j); c = self%xc(idx)
            pen = u(a) - u(b) - gap(j); r1 = v(a) - v(b)
            call contact_law(m, j, pen, r1, br, f, self%xbrc(idx))
            d0 = un(a) - un(b) - gap(j)
            if (located .and. o%ph_open(c) .and. self%xbrc(idx) /= B_OFF .and. d0 > 0.0_dp .and. &
                (tracks(o, TRACK_CONTACT_PEAKS) .or. tracks(o, TRACK_PHASES))) then
               ! as the pair contacts (measure_kernel): the start's force by the whole law
               r0 = vn(a) - vn(b)
               call contact_law(m, j, d0, r0, br0, f0)
               kc = m%con_par(P_STIFF, j); cc = 0.0_dp
               if (m%con_law(j) == LAW_KELVIN) cc = m%con_par(P_DAMPING, j)
               fr0 = 0.0_dp; fr1 = 0.0_dp
               if (f0 > 0.0_dp) fr0 = kc*r0 + cc*(an(a) - an(b))
               if (f > 0.0_dp) fr1 = kc*r1 + cc*(acc(a) - acc(b))
               call observer_contact_step_peaks(o, c, .true., hl, d0, r0, f0, fr0, pen, r1, f, fr1)
            end if
            if (h > 0.0_dp .and. ((self%xbrc(idx) /= B_OFF) .neqv. o%ph_open(c))) &
               call observer_phase_change(o, c, self%xbrc(idx) /= B_OFF, pen, f, d0, vn(a) - vn(b), &
                                          an(a) - an(b), pen, r1, acc(a) - acc(b), t, h, [a, b])
            if (tracks(o, TRACK_PHASES)) &
               call observer_phase_peaks(o%ph_open(c), pen, f, o%ph_pen(c), o%ph_f(c))
            if (tracks(o, TRACK_CONTACT_PEAKS)) &
               call observer_contact_peaks(pen, f, o%pen_max(c), o%force_max(c))
         end do
         if (.not. tracks(o, TRACK_LINK_PEAKS)) return
         do idx = 1, size(self%blo)
            j = self%blo(idx); l = self%bl(idx); a = m%link_a(l); b = m%link_b(l)
            call raise_to(o%link_force_absmax(j), abs(self%bfc(idx)))
            call raise_to(o%link_du_absmax(j), abs(self%bdu(idx)))
            if (located) call observer_link_step_extremum(LINK_BILINEAR, m%link_par(:, l), hl, &
                                                          un(a) - un(b), vn(a) - vn(b), 0.0_dp, &
                                                          self%bdu(idx), v(a) - v(b), 0.0_dp, &
                                                          self%bfc(idx), o%link_force_absmax(j), &
                                                          o%link_du_absmax(j))
         end do
      end associate
   end subroutine measure_others

   !> Every linear link's peaks from the maxima of its node or pair: |f| = |k|·max|Δu| of a
   !> spring or bar, |c|·max|Δv| of a dashpot (rounding is monotone: the same numbers as
   !> the largest |k Δu| over the samples).
   subroutine link_peaks(self, m, o)
      class(chain_newmark_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      type(observer_t), intent(inout) :: o
      integer :: j, a, b, q, i, idx
      real(dp) :: umax, vmax
      if (.not. tracks(o, TRACK_LINK_PEAKS)) return
      do j = 1, m%nlink
         a = m%link_a(j); b = m%link_b(j)
         select case (m%link_kind(j))
         case (LINK_SPRING, LINK_BAR, LINK_DASHPOT)
         case default
            cycle
         end select
         vmax = 0.0_dp
         if (a > 0 .and. b > 0) then
            umax = self%pumax(min(a, b))
            if (m%link_kind(j) == LINK_DASHPOT) vmax = self%pvmax(min(a, b))
         else
            umax = self%gumax(a + b)
            if (m%link_kind(j) == LINK_DASHPOT) vmax = self%gvmax(a + b)
         end if
         idx = model_link_index(m, j)
         o%link_du_absmax(idx) = umax
         if (m%link_kind(j) == LINK_DASHPOT) then
            o%link_force_absmax(idx) = abs(m%link_par(L_DAMP, j))*vmax
         else
            o%link_force_absmax(idx) = abs(m%link_par(L_STIFF, j))*umax
         end if
      end do
      ! a chain's: the spring, then (where c > 0) the dashpot of each node
      do q = 1, m%nchain
         associate (ch => m%chain(q))
            idx = ch%link0
            do i = 1, ch%n
               j = ch%first + i - 1
               idx = idx + 1
               o%link_du_absmax(idx) = self%gumax(j)
               o%link_force_absmax(idx) = abs(ch%k(i))*self%gumax(j)
               if (.not. allocated(ch%c)) cycle
               if (.not. (ch%c(i) > 0.0_dp)) cycle
               idx = idx + 1
               o%link_du_absmax(idx) = self%gumax(j)
               o%link_force_absmax(idx) = ch%c(i)*self%gvmax(j)
            end do
         end associate
      end do
   end subroutine link_peaks

   !> δ and force of the contacts which (0 elsewhere): the history's columns.
   subroutine contact_states(self, m, which, pen, force, st)
      class(chain_newmark_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      integer, intent(in) :: which(:)
      real(dp), allocatable, intent(inout) :: pen(:), force(:)
      integer, intent(out) :: st
      integer :: idx, j, i, a, b, scheme, law
      integer(int8) :: br
      real(dp) :: gap, par(NPAR_CONTACT), rate
      deallocate (pen, force)
      allocate (pen(model_ncontacts(m)), force(model_ncontacts(m)), stat=st)
      if (st /= 0) return
      pen = 0.0_dp; force = 0.0_dp
      do idx = 1, size(which)
         j = which(idx)
         call model_contact_at(m, j, a, b, gap, scheme, law, par)
         pen(j) = self%u(a) - self%u(b) - gap
         rate = self%v(a) - self%v(b)
         ! its committed branch: a pair contact's or another's
         br = B_OFF
         i = min(a, b)
         if (a > 0 .and. b > 0) then
            if (pair_contact(self, i) == j) br = self%pbrc(i)
         end if
         do i = 1, size(self%xc)
            if (self%xc(i) == j) br = self%xbrc(i)
         end do
         force(j) = 0.0_dp
         if (br == B_ON) force(j) = par(P_STIFF)*pen(j)
         if (br == B_ON .and. law == LAW_KELVIN) force(j) = force(j) + kelvin_damping(j)*rate
      end do
   contains
      !> the damping the sweep gives contact j
      real(dp) function kelvin_damping(j) result(c)
         integer, intent(in) :: j
         integer :: q
         c = 0.0_dp
         do q = 1, self%n - 1
            if (pair_contact(self, q) == j) c = self%pc(q*self%sc)
         end do
         do q = 1, size(self%xc)
            if (self%xc(q) == j) c = m%con_par(P_DAMPING, self%xg(q))
         end do
      end function kelvin_damping
   end subroutine contact_states

   !> Force and elongation of the links which (0 elsewhere): the history's columns.
   subroutine link_states(self, m, which, lf, ld, st)
      class(chain_newmark_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      integer, intent(in) :: which(:)
      real(dp), allocatable, intent(out) :: lf(:), ld(:)
      integer, intent(out) :: st
      integer :: idx, j, a, b, q, kind
      real(dp) :: par(NPAR_LINK)
      allocate (lf(model_nlinks(m)), ld(model_nlinks(m)), stat=st)
      if (st /= 0) return
      lf = 0.0_dp; ld = 0.0_dp
      do idx = 1, size(which)
         j = which(idx)
         call model_link_at(m, j, kind, a, b, par)
         ld(j) = self%u(a) - self%u(b)
         select case (kind)
         case (LINK_DASHPOT)
            lf(j) = par(L_DAMP)*(self%v(a) - self%v(b))
         case (LINK_BILINEAR)
            do q = 1, size(self%blo)
               if (self%blo(q) == j) lf(j) = self%bfc(q)
            end do
         case default
            lf(j) = par(L_STIFF)*ld(j)
         end select
      end do
   end subroutine link_states

   !> [kinetic, links, contacts] energy of the committed state: ½ vᵀMv, the springs' ½ k Δu²
   !> and the bilinear springs' recoverable energy, the contacts' elastic energy at max(δ, 0)
   !> (as recoverable_energy).
   function energies(self, m) result(e)
      class(chain_newmark_t), intent(in) :: self
      type(model_t), intent(in) :: m
      real(dp) :: e(3)
      integer :: i, n, idx, j
      real(dp) :: du, pen, eb
      n = self%n
      e = 0.0_dp
      associate (u => self%u, v => self%v)
         do i = 1, n
            e(1) = e(1) + 0.5_dp*m%mass(i)*v(i)*v(i)
            if (self%chain_links) then
               e(2) = e(2) + 0.5_dp*m%chain(1)%k(i)*u(i)*u(i)
            else
               e(2) = e(2) + 0.5_dp*self%kg(i)*u(i)*u(i)
            end if
         end do
         if (self%pair_links) then
            do i = 1, n - 1
               du = u(i) - u(i + 1)
               e(2) = e(2) + 0.5_dp*self%kp(i)*du*du
            end do
         end if
         do idx = 1, size(self%bl)
            j = self%bl(idx)
            call bilinear_energy(m%link_par(L_STIFF, j), m%link_par(L_YIELD, j), &
                                 m%link_par(L_HARDENING, j), self%bfc(idx), self%bdu(idx), eb)
            e(2) = e(2) + eb
         end do
         do i = 1, n - 1
            if (pair_contact(self, i) == 0) cycle
            pen = self%psgn(i*self%ss)*(u(i) - u(i + 1)) - self%pgap(i*self%sg)
            if (pen > 0.0_dp) e(3) = e(3) + 0.5_dp*self%pk(i*self%sk)*pen*pen
         end do
         do idx = 1, size(self%xg)
            j = self%xg(idx)
            pen = u(m%con_a(j)) - u(m%con_b(j)) - m%con_gap(j)
            e(3) = e(3) + contact_elastic_energy(m%con_law(j), m%con_par(:, j), max(pen, 0.0_dp))
         end do
      end associate
   end function energies

   !> Every pair contact shares its sign, gap, stiffness and law, and every node its mass
   !> (stride 0 for all): the usual [[chain]].
   pure logical function from_chain_of_one_kind(self) result(one)
      class(chain_newmark_t), intent(in) :: self
      one = self%ss == 0 .and. self%sg == 0 .and. self%sk == 0 .and. self%sc == 0 .and. &
            self%sl == 0 .and. self%sm == 0
   end function from_chain_of_one_kind

   !> The contact of pair (i, i+1) among all the model's contacts (0: none).
   pure integer function pair_contact(self, i) result(c)
      class(chain_newmark_t), intent(in) :: self
      integer, intent(in) :: i
      if (self%pc0 >= 0) then
         c = 0
         if (i >= 1 .and. i < self%n) c = self%pc0 + i
      else
         c = self%pcon(i)
      end if
   end function pair_contact

   subroutine swap(x, y)
      real(dp), allocatable, intent(inout) :: x(:), y(:)
      real(dp), allocatable :: tmp(:)
      call move_alloc(x, tmp); call move_alloc(y, x); call move_alloc(tmp, y)
   end subroutine swap

   subroutine swap_int8(x, y)
      integer(int8), allocatable, intent(inout) :: x(:), y(:)
      integer(int8), allocatable :: tmp(:)
      call move_alloc(x, tmp); call move_alloc(y, x); call move_alloc(tmp, y)
   end subroutine swap_int8
end module martello_chain_newmark
