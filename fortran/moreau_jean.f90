!> Moreau–Jean time stepping (Moreau 1988; Jean 1999; Acary & Brogliato 2008, §10.1) for
!> scenes with restitution and Lagrange contacts, penalty contacts and links being smooth
!> forces:
!>
!>   M (v_{k+1} − v_k) = h f_θ + Bᵀ p_{k+1},   q_{k+1} = q_k + h v_θ,   x_θ = θ x_{k+1} + (1−θ) x_k,
!>
!> with the smooth forces linearised at the start of the step with their tangents K, C
!> (f_θ ≈ f_ext,θ − fint_k − θ K Δq − θ C Δv), so that the step matrix is
!> Ŵ = M + hθ C + h²θ² K (banded, factorised once a step) and the free velocity is
!> v_free = v_k + Ŵ⁻¹ h (f_ext,θ − fint_k − hθ K v_k) (Acary & Brogliato 2008, eq. 10.12).
!> Contacts are predicted active when the gap at mid-step, extrapolated from the start,
!> has closed: δ(q_k + ½h v_k) ≥ 0 (the index set of Siconos' MoreauJeanOSI, γ = ½ whatever
!> θ). On them Newton's impact law holds at the velocity level,
!>
!>   0 ≤ ġ_{k+1} + e ġ_k ⊥ p_{k+1} ≥ 0,   ġ = B v = v_b − v_a = −δ̇,
!>
!> an LCP on the Delassus operator W = B Ŵ⁻¹ Bᵀ, the shared impulse problem (martello_impulse,
!> docs/impulse.md: Lemke for up to LEMKE_MAX active contacts, projected Gauss–Seidel beyond,
!> on a tridiagonal W when Ŵ is diagonal). Lagrange contacts are the same law with e = their
!> restitution (default 0).
!>
!> Discrete energy identity (linear forces): E_{k+1} − E_k = −(θ − ½)(‖Δv‖²_M + ‖Δq‖²_K)
!> + Δqᵀ f_ext,θ + ġ_θᵀ p_{k+1}; the impulse work ġ_θ p = (1 − θ(1+e)) ġ_k p is ≤ 0 iff
!> θ(1+e) ≤ 1. E_IMPACT accumulates −ġ_θᵀ p; the θ-dissipation is what E_BALANCE shows
!> (zero up to round-off for θ = ½ and linear forces).
!>
!> A stepper of the fixed-step strategy (martello_fixed_step, docs/run-layer.md): the step and
!> its impulse problem are here, the time loop and the measurement are the strategy's and
!> the observer's.
module martello_moreau_jean
   use martello_kinds, only: dp, i8
   use martello_lapack, only: dgbtrf, dgbtrs
   use martello_status
   use martello_model, only: model_t, model_bandwidth, rigid_contacts
   use martello_element_rows, only: rows_t, rows_init, rows_append, row_lo, row_hi, row_dot
   use martello_band_matrix, only: band_t, band_init, band_matvec, band_pin
   use martello_assembly, only: internal_forces, external_forces, mech_commit, assemble_mass, mass_times
   use martello_observer, only: observer_t, observer_work, observer_fail, observer_open_phase, &
      observer_close_phase
   use martello_run_quantities, only: C_NEWTON, C_RESIDUALS, C_FACTORIZATIONS, C_EVENTS, C_JACOBIANS
   use martello_integrator_settings, only: integrator_settings_t
   use martello_fixed_step, only: stepper_t, stepper_start, contact_state
   use martello_impulse, only: contact_graph_t, contact_graph, delassus_columns, b_dot, &
      delassus_bandwidth, delassus_diagonal_band, newton_impulses, newton_impulses_band, kkt_bandwidth, &
      lcp_work_reals, LEMKE_MAX, IMPULSE_OK, IMPULSE_NO_MEMORY
   use martello_linalg, only: lapack_status
   implicit none
   private
   public :: moreau_jean_t

   type, extends(stepper_t) :: moreau_jean_t
      integer :: kd = 0, na = 0, kw = 0, iters = 0
      real(dp) :: theta = 0.5_dp, hth = 0.0_dp, hth2 = 0.0_dp
      logical :: thomas = .false.
      real(dp), allocatable :: fint(:), fint_n(:), fext(:), fext_n(:), rhs(:), work(:)
      real(dp), allocatable :: e_con(:), p(:), p_prev(:), ph_last(:)
      integer, allocatable :: act(:), pos(:), ipiv(:)
      !> each contact's row B_c (ġ_c = B_c v, martello_impulse): its penetration row negated,
      !> the fixed nodes left out
      type(rows_t) :: b
      type(contact_graph_t) :: graph   !< which rigid contacts share a node (martello_impulse)
      logical, allocatable :: rigid(:), movable(:)
      ! Delassus operator: dense (Lemke) and band (PGS), the columns Ŵ⁻¹Bᵀ (kd > 0), LCP data
      real(dp), allocatable :: wd_(:, :), wb(:, :), zcol(:, :), qlcp(:), zlcp(:), gref(:), eact(:)
      !> Ŵ before its factorisation (kd > 0 and more than LEMKE_MAX contacts): the band of the
      !> saddle-point form of the LCP (newton_impulses_band)
      real(dp), allocatable :: w0(:, :)
      type(band_t) :: kband, cband, what
   contains
      procedure :: init
      procedure :: step
   end type moreau_jean_t

contains

   !> The state at t = 0 with the tangents K, C of the smooth forces committed there.
   subroutine init(self, m, s, o, stat)
      class(moreau_jean_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      type(integrator_settings_t), intent(in) :: s
      type(observer_t), intent(inout) :: o
      integer, intent(out) :: stat
      integer :: n, nc
      character(len=256) :: msg
      stat = MARTELLO_OK
      call stepper_start(self, m, s, o, stat)
      if (stat /= MARTELLO_OK) return
      n = m%n; nc = m%ncontact
      self%advice = 'the linearised smooth forces need a smaller step'
      self%velocity_jump_phases = .true.   ! penalty phases valued with v_k, v_{k+1}
      self%theta = s%theta
      self%hth = self%h*self%theta
      self%hth2 = self%hth*self%hth
      self%kd = model_bandwidth(m)
      allocate (self%fint(0:n), self%fint_n(0:n), self%fext(0:n), self%fext_n(0:n), &
                self%rhs(0:n), self%work(0:n), self%ipiv(n), &
                self%e_con(nc), self%p(nc), self%p_prev(nc), self%ph_last(nc), &
                self%act(nc), self%pos(nc), self%rigid(nc), self%movable(nc), stat=stat)
      if (stat /= 0) call out_of_memory('the state of Moreau-Jean', REAL_BYTES*(6*(n + 1.0_dp) + &
                                        4.0_dp*nc) + INT_BYTES*(n + 6.0_dp*nc), FIX_SMALLER_SCENE, stat, msg)
      if (stat == MARTELLO_OK) call band_init(self%kband, n, self%kd, stat, msg)
      if (stat == MARTELLO_OK) call band_init(self%cband, n, self%kd, stat, msg)
      if (stat == MARTELLO_OK) call band_init(self%what, n, self%kd, stat, msg)
      if (stat == MARTELLO_OK) then
         call rigid_contacts(m, self%rigid, self%e_con, self%movable)
         call gap_rate_rows(stat)
         if (stat == 0) call contact_graph(n, self%b, self%movable, self%graph, stat)
         if (stat /= 0) call out_of_memory('the contact graph of Moreau-Jean', &
                                           (INT_BYTES + REAL_BYTES)*(n + 2.0_dp + 2*nc), FIX_SMALLER_SCENE, stat, msg)
      end if
      if (stat /= MARTELLO_OK) then
         call observer_fail(o, MARTELLO_ERR_MEMORY, 0.0_dp, msg, stat)
         return
      end if
      self%p = 0.0_dp; self%p_prev = 0.0_dp; self%ph_last = 0.0_dp
      self%kband%ab = 0.0_dp; self%cband%ab = 0.0_dp
      call internal_forces(m, self%ms, self%u, self%v, self%fint, self%kband%ab, 1.0_dp, 0.0_dp, &
                           self%cband%ab)
      call mech_commit(m, self%ms, self%u)
      call external_forces(m, self%mrow, 0.0_dp, self%fext)
      o%counters(C_RESIDUALS) = o%counters(C_RESIDUALS) + 1_i8
      o%counters(C_JACOBIANS) = o%counters(C_JACOBIANS) + 1_i8
      call contact_state(self, m, self%p, self%h)

   contains

      !> self%b: B_c = −(contact c's row) on its free nodes.
      subroutine gap_rate_rows(st)
         integer, intent(out) :: st
         integer :: c, q
         call rows_init(self%b, nc, 2, st)
         do c = 1, nc
            if (st /= 0) return
            associate (nd => m%con%node(row_lo(m%con, c):row_hi(m%con, c)), &
                       cf => m%con%coef(row_lo(m%con, c):row_hi(m%con, c)))
               call rows_append(self%b, [(merge(0, nd(q), m%fixed(nd(q))), q = 1, size(nd))], -cf, st)
            end associate
         end do
      end subroutine gap_rate_rows
   end subroutine init

   !> One step: free velocity, index set, impulses, positions; the smooth forces and their
   !> tangents committed at the new state; works and the phases of the rigid contacts.
   subroutine step(self, m, t, o, stat)
      class(moreau_jean_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      real(dp), intent(in) :: t
      type(observer_t), intent(inout) :: o
      integer, intent(out) :: stat
      integer :: n, nc, i, j, c, q, info, code
      real(dp) :: h, t_prev, theta, hth, wdl, wll, wcl, dw, gdot_theta, d_theta
      character(len=512) :: msg

      stat = MARTELLO_OK
      n = self%n; nc = self%nc; h = self%h; theta = self%theta; hth = self%hth
      t_prev = self%t0
      associate (u => self%u, v => self%v, un => self%un, vn => self%vn, a => self%a, &
                 fint => self%fint, fint_n => self%fint_n, fext => self%fext, &
                 fext_n => self%fext_n, rhs => self%rhs, work => self%work, p => self%p, &
                 p_prev => self%p_prev, act => self%act, &
                 na => self%na, kband => self%kband, cband => self%cband, what => self%what, &
                 fixed_nodes => self%fixed_nodes)
         fint_n = fint; fext_n = fext
         call external_forces(m, self%mrow, t, fext)

         ! Ŵ = M + hθ C + h²θ² K from the tangents of the committed state
         what%ab = self%hth2*kband%ab + hth*cband%ab
         call assemble_mass(m, 1.0_dp, what)
         do i = 1, size(fixed_nodes)
            call band_pin(what, fixed_nodes(i))
         end do
         ! free velocity: Ŵ Δv_free = h (f_ext,θ − fint_k − hθ K v_k)
         call band_matvec(kband, vn(1:n), work(1:n))
         do i = 1, n
            rhs(i) = (h*theta)*fext(i) + (h*(1.0_dp - theta))*fext_n(i) - h*fint_n(i) - h*hth*work(i)
         end do
         rhs(0) = 0.0_dp
         rhs(fixed_nodes) = 0.0_dp
         if (self%kd > 0 .and. nc > LEMKE_MAX) then
            if (.not. allocated(self%w0)) then
               allocate (self%w0, mold=what%ab, stat=info)
               if (info /= 0) then
                  call no_memory('the step matrix copy', REAL_BYTES*size(what%ab))
                  return
               end if
            end if
            self%w0 = what%ab
         end if
         call factorise(info)
         if (info /= 0) then
            call lapack_status('dgbtrf', info, code, msg)
            call observer_fail(o, code, t_prev, 'Moreau-Jean: the step matrix M + h theta C + '// &
                               '(h theta)^2 K is singular ('//trim(msg)//')', stat)
            return
         end if
         call solve_what(rhs(1:n))
         v(1:n) = vn(1:n) + rhs(1:n)           ! v_free
         v(0) = 0.0_dp

         ! index set and impulses
         call active_set()
         p_prev = p
         p = 0.0_dp
         if (na > 0) then
            call impulses(info)
            if (stat /= MARTELLO_OK) return
            ! v = v_free + Ŵ⁻¹ Bᵀ p
            work = 0.0_dp
            do j = 1, na
               c = act(j)
               do q = row_lo(self%b, c), row_hi(self%b, c)
                  work(self%b%node(q)) = work(self%b%node(q)) + self%b%coef(q)*p(c)
               end do
            end do
            work(0) = 0.0_dp
            call solve_what(work(1:n))
            v(1:n) = v(1:n) + work(1:n)
         end if
         v(fixed_nodes) = 0.0_dp
         ! q_{k+1} = q_k + h (θ v_{k+1} + (1−θ) v_k), in the order of Siconos' updatePosition
         do i = 1, n
            u(i) = ((h*theta)*v(i) + (h*(1.0_dp - theta))*vn(i)) + un(i)
         end do
         u(fixed_nodes) = un(fixed_nodes)
         a(1:n) = (v(1:n) - vn(1:n))/h         ! mean acceleration of the step (impulses included)
         d_theta = theta_dissipation()

         ! smooth forces and tangents at the new state, committed
         kband%ab = 0.0_dp; cband%ab = 0.0_dp
         call internal_forces(m, self%ms, u, v, fint, kband%ab, 1.0_dp, 0.0_dp, cband%ab)
         call mech_commit(m, self%ms, u, wdl, wll, wcl)
         o%counters(C_RESIDUALS) = o%counters(C_RESIDUALS) + 1_i8
         o%counters(C_JACOBIANS) = o%counters(C_JACOBIANS) + 1_i8

         ! energy: external work Δqᵀ f_ext,θ; impulse work ġ_θ p (dissipated: its negative)
         call observer_work(o, damping=wdl, links=wll, contact=wcl)
         dw = 0.0_dp
         do i = 1, n
            if (.not. m%fixed(i)) dw = dw + (theta*fext(i) + (1.0_dp - theta)*fext_n(i))*(u(i) - un(i))
         end do
         call observer_work(o, external=dw)
         do j = 1, na
            c = act(j)
            gdot_theta = theta*b_dot(self%b, c, v(1:)) + (1.0_dp - theta)*b_dot(self%b, c, vn(1:))
            call observer_work(o, impact=-gdot_theta*p(c))
         end do
         call observer_work(o, impact=d_theta)
      end associate
      call contact_state(self, m, self%p, self%h)
      call rigid_phases()

   contains

      !> LU of Ŵ once a step (a diagonal Ŵ needs none); info > 0: singular. A chain (kd = 1)
      !> is factorised without pivoting — Ŵ is symmetric positive definite, diagonally
      !> dominant while M dominates h²θ²K — with dgbtrf taking over if a pivot collapses.
      subroutine factorise(inf)
         integer, intent(out) :: inf
         integer :: k
         inf = 0
         o%counters(C_FACTORIZATIONS) = o%counters(C_FACTORIZATIONS) + 1_i8
         associate (what => self%what, thomas => self%thomas, kd => self%kd)
            thomas = .false.
            select case (kd)
            case (0)
               do k = 1, n
                  if (what%ab(1, k) == 0.0_dp) then
                     inf = k; return
                  end if
               end do
            case (1)
               ! A(k,k) = ab(3,k), A(k+1,k) = ab(4,k), A(k,k+1) = ab(2,k+1)
               what%d = what%ab(3, :)
               thomas = .true.
               do k = 2, n
                  if (abs(what%d(k - 1)) <= 1.0e-14_dp*abs(what%ab(3, k - 1))) then
                     thomas = .false.; exit
                  end if
                  what%dl(k) = what%ab(4, k - 1)/what%d(k - 1)
                  what%d(k) = what%d(k) - what%dl(k)*what%ab(2, k)
               end do
               if (thomas .and. what%d(n) == 0.0_dp) thomas = .false.
               if (.not. thomas) call dgbtrf(n, n, kd, kd, what%ab, size(what%ab, 1), self%ipiv, inf)
            case default
               call dgbtrf(n, n, kd, kd, what%ab, size(what%ab, 1), self%ipiv, inf)
            end select
         end associate
      end subroutine factorise

      subroutine solve_what(x)
         real(dp), intent(inout) :: x(:)
         integer :: inf, k
         associate (what => self%what)
            if (self%kd == 0) then
               x = x/what%ab(1, :)
            else if (self%thomas) then
               do k = 2, n
                  x(k) = x(k) - what%dl(k)*x(k - 1)
               end do
               x(n) = x(n)/what%d(n)
               do k = n - 1, 1, -1
                  x(k) = (x(k) - what%ab(2, k + 1)*x(k + 1))/what%d(k)
               end do
            else
               call dgbtrs('N', n, self%kd, self%kd, 1, what%ab, size(what%ab, 1), self%ipiv, x, n, inf)
            end if
         end associate
      end subroutine solve_what

      !> Acary's index set: δ(q_k + ½h v_k) ≥ 0, the gap extrapolated to mid-step has closed.
      subroutine active_set()
         real(dp) :: dpred
         integer :: k
         associate (na => self%na, act => self%act, pos => self%pos, un => self%un, vn => self%vn)
            na = 0
            pos = 0
            do k = 1, nc
               if (.not. self%movable(k)) cycle
               dpred = row_dot(m%con, k, un) + (0.5_dp*h)*row_dot(m%con, k, vn) - m%con_gap(k)
               if (dpred >= 0.0_dp) then
                  na = na + 1
                  act(na) = k
                  pos(k) = na
               end if
            end do
         end associate
      end subroutine active_set

      !> W of the active contacts (martello_impulse) and Newton's law on them; p(act) the
      !> impulses. ġ_free = B v_free, ġ_ref = B v_k.
      subroutine impulses(inf)
         integer, intent(out) :: inf
         integer :: ii, jj, k, kk
         logical :: banded
         associate (na => self%na, kw => self%kw, kd => self%kd, act => self%act, &
                    pos => self%pos, v => self%v, vn => self%vn, &
                    e_con => self%e_con, what => self%what, iters => self%iters, p => self%p, &
                    p_prev => self%p_prev)
            inf = 0
            if (allocated(self%qlcp)) then
               if (size(self%qlcp) < na) deallocate (self%qlcp, self%zlcp, self%gref, self%eact)
            end if
            if (.not. allocated(self%qlcp)) then
               allocate (self%qlcp(nc), self%zlcp(nc), self%gref(nc), self%eact(nc), stat=inf)
               if (inf /= 0) call no_memory('the impulse problem', REAL_BYTES*4*nc)
               if (inf /= 0) return
            end if
            do ii = 1, na
               k = act(ii)
               self%qlcp(ii) = b_dot(self%b, k, v(1:))
               self%gref(ii) = b_dot(self%b, k, vn(1:))
               self%eact(ii) = e_con(k)
               self%zlcp(ii) = p_prev(k)                ! warm start from the last step (PGS)
            end do
            banded = .false.
            if (kd == 0) then
               ! Ŵ diagonal: W banded in the active ordering (tridiagonal for a chain)
               kw = delassus_bandwidth(self%graph, self%b, act(1:na), pos)
               call ensure_band(kw, inf)
               if (inf /= 0) return
               call delassus_diagonal_band(self%graph, self%b, act(1:na), pos, what%ab(1, :), kw, self%wb)
               call newton_impulses(self%qlcp(1:na), self%gref(1:na), self%eact(1:na), &
                                    self%zlcp(1:na), inf, iters, wb=self%wb, kw=kw)
            else
               ! beyond Lemke's size, when its band is narrow (a chain), the saddle-point form:
               ! O(n + na) a round where the dense W below costs O(n na + na³)
               if (na > LEMKE_MAX) then
                  kk = kkt_bandwidth(self%b, act(1:na), n, kd)
                  if (real(n + na, dp)*(kk + 1)**2 <= real(n, dp)*na*(kd + 1)) then
                     call newton_impulses_band(self%w0, kd, self%b, act(1:na), self%qlcp(1:na), &
                                               self%gref(1:na), self%eact(1:na), self%zlcp(1:na), inf, iters)
                     banded = inf == IMPULSE_OK
                     o%counters(C_NEWTON) = o%counters(C_NEWTON) + int(iters, i8)
                     iters = 0
                     if (inf == IMPULSE_NO_MEMORY) then
                        call no_memory('the saddle-point band of the LCP', REAL_BYTES*(3*kk + 3.0_dp)*(n + na))
                        return
                     end if
                  end if
               end if
            end if
            if (kd > 0 .and. .not. banded) then
               ! W = B Ŵ⁻¹ Bᵀ from the columns Ŵ⁻¹ B_jᵀ (one multi-right-hand-side solve)
               if (allocated(self%zcol)) then
                  if (size(self%zcol, 2) < na) deallocate (self%zcol)
               end if
               if (.not. allocated(self%zcol)) then
                  allocate (self%zcol(n, max(na, 1)), stat=inf)
                  if (inf /= 0) call no_memory('the Delassus columns', REAL_BYTES*n*max(na, 1))
                  if (inf /= 0) return
               end if
               self%zcol(:, 1:na) = 0.0_dp
               do jj = 1, na
                  k = act(jj)
                  do ii = row_lo(self%b, k), row_hi(self%b, k)
                     self%zcol(self%b%node(ii), jj) = self%b%coef(ii)
                  end do
               end do
               if (self%thomas) then
                  do jj = 1, na
                     call solve_what(self%zcol(:, jj))
                  end do
               else
                  call dgbtrs('N', n, kd, kd, na, what%ab, size(what%ab, 1), self%ipiv, self%zcol, n, inf)
               end if
               call ensure_dense(inf)
               if (inf /= 0) return
               call delassus_columns(self%b, act(1:na), self%zcol(:, 1:na), &
                                     self%wd_(1:na, 1:na))
               call newton_impulses(self%qlcp(1:na), self%gref(1:na), self%eact(1:na), &
                                    self%zlcp(1:na), inf, iters, w=self%wd_(1:na, 1:na))
            end if
            o%counters(C_NEWTON) = o%counters(C_NEWTON) + int(iters, i8)
            if (inf == IMPULSE_NO_MEMORY) then
               call no_memory('the work arrays of the LCP solver', REAL_BYTES*lcp_work_reals(na))
               return
            else if (inf /= IMPULSE_OK) then
               write (msg, '(a,i0,a,a,a,i0,a)') 'Moreau-Jean: the impulse LCP on ', na, &
                  ' active contacts failed at t = ', sci(t, 5), ' s (', iters, &
                  ' iterations; redundant constraints or a contact between immobile sides?)'
               call observer_fail(o, MARTELLO_ERR_NOT_CONVERGED, t_prev, msg, stat)
               return
            end if
            do ii = 1, na
               p(act(ii)) = self%zlcp(ii)
            end do
         end associate
      end subroutine impulses

      subroutine ensure_band(k, st)
         integer, intent(in) :: k
         integer, intent(out) :: st
         st = 0
         if (allocated(self%wb)) then
            if (size(self%wb, 1) < 2*k + 1 .or. size(self%wb, 2) < self%na) deallocate (self%wb)
         end if
         if (allocated(self%wb)) return
         allocate (self%wb(2*k + 1, max(self%na, nc)), stat=st)
         if (st /= 0) call no_memory('the band Delassus matrix', REAL_BYTES*(2*k + 1.0_dp)*max(self%na, nc))
      end subroutine ensure_band

      subroutine ensure_dense(st)
         integer, intent(out) :: st
         st = 0
         if (allocated(self%wd_)) then
            if (size(self%wd_, 1) < self%na) deallocate (self%wd_)
         end if
         if (allocated(self%wd_)) return
         allocate (self%wd_(self%na, self%na), stat=st)
         if (st /= 0) call no_memory('the Delassus matrix', REAL_BYTES*real(self%na, dp)**2)
      end subroutine ensure_dense

      !> An allocation of the step failed: the run fails with the out-of-memory line.
      subroutine no_memory(what, bytes)
         character(len=*), intent(in) :: what
         real(dp), intent(in) :: bytes
         write (msg, '(a,i0,a)') ' of Moreau-Jean for ', self%na, ' active contacts'
         call out_of_memory(what//trim(msg), bytes, FIX_SMALLER_SCENE, stat, msg)
         call observer_fail(o, MARTELLO_ERR_MEMORY, t_prev, msg, stat)
      end subroutine no_memory

      !> Contact phases of the rigid contacts (the penalty ones are the strategy's): a phase
      !> is a run of steps with p > 0; it starts at the instant t_k + (1−θ)h where the
      !> scheme's piecewise-linear path switches from v_k to v_{k+1} (q_{k+1} = q_k +
      !> (1−θ)h v_k + θh v_{k+1}), v_in is δ̇_k before the first impulse, v_out δ̇ after the
      !> last one, t_off the switching instant of the last impulse step (a single-step impact
      !> has t_off = t_on: it is instantaneous).
      subroutine rigid_phases()
         integer :: k
         real(dp) :: t_imp
         t_imp = t_prev + (1.0_dp - theta)*(t - t_prev)
         do k = 1, nc
            if (.not. self%rigid(k)) cycle
            if (self%p(k) > 0.0_dp) then
               if (.not. o%ph_open(k)) then
                  call observer_open_phase(o, k, t_imp, row_dot(m%con, k, self%vn))
                  o%counters(C_EVENTS) = o%counters(C_EVENTS) + 1_i8
               end if
               self%ph_last(k) = t_imp
            else if (o%ph_open(k)) then
               call observer_close_phase(o, k, self%ph_last(k), row_dot(m%con, k, self%vn))
            end if
         end do
      end subroutine rigid_phases
      !> The θ-method's numerical dissipation of the step, (θ − ½)(ΔvᵀMΔv + Δqᵀ(KΔq + CΔv))
      !> with the tangents K, C the step used (docs/moreau-jean.md "Energy"): 0 at θ = ½.
      !> The impulse work ġ_θ p alone may be negative for θ(1 + e) > 1; with this term the
      !> energy the impacts and the scheme took out is, and the balance is round-off for
      !> linear forces at any θ. Scratch: rhs and work (v_free is spent).
      real(dp) function theta_dissipation() result(d)
         d = 0.0_dp
         if (self%theta <= 0.5_dp) return
         associate (u => self%u, un => self%un, v => self%v, vn => self%vn, rhs => self%rhs, &
                    work => self%work)
            rhs(1:n) = u(1:n) - un(1:n)
            call band_matvec(self%kband, rhs(1:n), work(1:n))
            d = dot_product(rhs(1:n), work(1:n))
            rhs(1:n) = v(1:n) - vn(1:n)
            call band_matvec(self%cband, rhs(1:n), work(1:n))
            d = d + dot_product(u(1:n) - un(1:n), work(1:n))
            rhs(0) = 0.0_dp
            call mass_times(m, rhs, work)
            d = (self%theta - 0.5_dp)*(d + dot_product(rhs(1:n), work(1:n)))
         end associate
      end function theta_dissipation
   end subroutine step
end module martello_moreau_jean
