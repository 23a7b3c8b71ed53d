!> The lean two-sweep kernel of the benchmark's chain (docs/performance.md "The fused step
!> against a lean kernel"): what a person writing this one chain by hand would run, to hold
!> the library's fused chain step against. Newmark average acceleration on n oscillators
!> (m = 1 kg, k alternating 100 and 400 N/m, a dashpot to ground of 5 % damping, linear
!> contacts ε = 1e5 N/m through 10 mm gaps between neighbours, ground acceleration 3 sin 8t),
!> the same equations and the same Newton iteration as the fused step on the same chain
!> (fortran/chain/chain_step.f90, its sweeps forward_sweep.inc and back_sweep.inc): the
!> residual linearised about the committed state, forward-substituted with the kept factors
!> J = L D Lᵀ (reciprocal pivots), a backward sweep for Δu, u, v, a and the elements, and a
!> refactorisation where a contact changed branch. Nothing else: no works, no peaks, no
!> observer, no flags or strides, every parameter a constant. Its ten per-node arrays lie in
!> one block, 256 B apart modulo a 4 kB page, as the library's (arrays allocated one by one
!> would start at the same page offset and their streams share L1 sets: cachegrind, n = 1e5,
!> 9.2 L1 misses per DOF-step against 2.4): the yardstick is a kernel without that handicap.
!>
!>     lean_chain N STEPS
!>
!> prints one JSON line: the wall and CPU seconds of the time loop, ns per DOF-step, the solves
!> and factorisations, and u of the first and last node at the end (the library's history gives
!> the same to round-off: the same computation).
program lean_chain
   use, intrinsic :: iso_fortran_env, only: int8, int64, output_unit
   implicit none
   integer, parameter :: dp = kind(1.0d0)
   real(dp), parameter :: M = 1.0_dp, K1 = 100.0_dp, K2 = 400.0_dp, ZETA = 0.05_dp, &
                          GAP = 0.01_dp, EPS = 1.0e5_dp, AMP = 3.0_dp, OMEGA = 8.0_dp, &
                          DT = 1.0e-3_dp, BETA = 0.25_dp, GAMMA = 0.5_dp
   integer(int8), parameter :: OFF = 0, ON = 1
   integer, parameter :: NARR = 10, PAGE = 512, SLOT = 32    ! in doubles: 4 kB, 256 B
   integer :: n, steps, k, i, it, len, at(NARR), tmp
   integer, parameter :: U_ = 1, V_ = 2, A_ = 3, UN_ = 4, VN_ = 5, AN_ = 6, RP_ = 7, FE_ = 8, &
                         KG_ = 9, CG_ = 10
   integer(int64) :: c0, c1, rate, solves, factorisations
   real(dp) :: cm, cv, ca, cb, acc, t, cpu0, cpu1
   real(dp), allocatable :: blk(:)
   integer(int8), allocatable :: br(:), brf(:)
   logical :: flipped, factored
   character(len=32) :: arg

   call get_command_argument(1, arg); read (arg, *) n
   call get_command_argument(2, arg); read (arg, *) steps
   cm = 1.0_dp/(BETA*DT*DT); cv = GAMMA/(BETA*DT)
   ca = 1.0_dp/(BETA*DT); cb = (0.5_dp - BETA)/BETA
   ! array j (its entry 0) at blk(at(j)): whole pages apart, plus j slots of 256 B
   len = (n + 1 + PAGE - 1)/PAGE*PAGE
   at = [((i - 1)*(len + SLOT) + 1, i = 1, NARR)]
   allocate (blk(NARR*(len + SLOT)), br(0:n), brf(0:n))
   blk = 0.0_dp; br = OFF; brf = OFF
   do i = 1, n
      blk(at(KG_) + i) = merge(K1, K2, mod(i - 1, 2) == 0)
      blk(at(CG_) + i) = 2.0_dp*ZETA*sqrt(blk(at(KG_) + i)*M)
   end do
   factored = .false.; solves = 0; factorisations = 0
   call system_clock(c0, rate)
   call cpu_time(cpu0)
   do k = 1, steps
      tmp = at(U_); at(U_) = at(UN_); at(UN_) = tmp
      tmp = at(V_); at(V_) = at(VN_); at(VN_) = tmp
      tmp = at(A_); at(A_) = at(AN_); at(AN_) = tmp
      t = k*DT
      acc = -AMP*sin(OMEGA*t)
      associate (u => blk(at(U_):at(U_) + n), v => blk(at(V_):at(V_) + n), a => blk(at(A_):at(A_) + n), &
                 un => blk(at(UN_):at(UN_) + n), vn => blk(at(VN_):at(VN_) + n), &
                 an => blk(at(AN_):at(AN_) + n), fe => blk(at(FE_):at(FE_) + n), &
                 rp => blk(at(RP_) + 1:at(RP_) + n), kg => blk(at(KG_) + 1:at(KG_) + n), &
                 cg => blk(at(CG_) + 1:at(CG_) + n))
         if (factored) then
            call forward(n, acc, vn, an, cg, rp, brf, fe)
            solves = solves + 1
         else
            rp = 0.0_dp; fe = 0.0_dp
         end if
         call backward(n, .true., rp, u, v, a, un, vn, an, kg, cg, br, brf, fe, flipped)
         do it = 1, 8
            if (.not. flipped .and. factored) exit
            brf = br
            call refactor(n, acc, a, kg, cg, brf, fe, rp, factored)
            factorisations = factorisations + 1; solves = solves + 1
            call backward(n, .false., rp, u, v, a, un, vn, an, kg, cg, br, brf, fe, flipped)
         end do
      end associate
      if (flipped .or. .not. factored) error stop 'lean_chain: a step did not settle in 8 solves'
   end do
   call system_clock(c1)
   call cpu_time(cpu1)
   write (output_unit, '(a,i0,a,i0,a,es14.7,a,es14.7,a,es14.7,a,i0,a,i0,a,es25.17,a,es25.17,a)') &
      '{"n": ', n, ', "steps": ', steps, ', "wall_s": ', real(c1 - c0, dp)/rate, ', "cpu_s": ', cpu1 - cpu0, &
      ', "ns_per_dof_step": ', real(c1 - c0, dp)/rate/(real(n, dp)*steps)*1.0e9_dp, &
      ', "solves": ', solves, ', "factorizations": ', factorisations, ', "u_first": ', &
      blk(at(U_) + 1), ', "u_last": ', blk(at(U_) + n), '}'

contains


   !> r = M a₀ + f_c + C Δv₀ − f_ext at u = uₙ (exact while no branch changes),
   !> forward-substituted with the kept factors: fe ← y
   subroutine forward(n, acc, vn, an, cg, rp, brf, fe)
      integer, intent(in) :: n
      real(dp), intent(in) :: acc, vn(0:n), an(0:n), cg(n), rp(n)
      integer(int8), intent(in) :: brf(0:n)
      real(dp), intent(inout) :: fe(0:n)
      real(dp) :: a0, dv0, y, l
      integer :: i
      y = 0.0_dp; l = 0.0_dp
      do i = 1, n
         a0 = -ca*vn(i) - cb*an(i)
         dv0 = DT*((1.0_dp - GAMMA)*an(i) + GAMMA*a0)
         y = M*(acc - a0) - fe(i) - cg(i)*dv0 - l*y
         fe(i) = y
         l = 0.0_dp
         if (i < n) then
            if (brf(i) == ON) l = -EPS*rp(i)
         end if
      end do
   end subroutine forward

   !> Δu = D⁻¹y − Lᵀ Δu; u, v, a by the Newmark relations (from u = uₙ, or from the
   !> iterate); the springs, dashpots and contacts at the new state: fe ← f_int, br the
   !> contacts' branches; flipped: a branch differs from the factors'
   subroutine backward(n, from_start, rp, u, v, a, un, vn, an, kg, cg, br, brf, fe, flipped)
      integer, intent(in) :: n
      logical, intent(in) :: from_start
      real(dp), intent(in) :: rp(n), un(0:n), vn(0:n), an(0:n), kg(n), cg(n)
      real(dp), intent(inout) :: u(0:n), v(0:n), a(0:n), fe(0:n)
      integer(int8), intent(inout) :: br(0:n)
      integer(int8), intent(in) :: brf(0:n)
      logical, intent(out) :: flipped
      real(dp) :: x, ui, vi, ai, u1, fi, f1, pen, f
      integer :: i
      integer(int8) :: b
      flipped = .false.; x = 0.0_dp; u1 = 0.0_dp; f1 = 0.0_dp
      do i = n, 1, -1
         f = 0.0_dp
         if (i < n) then
            if (brf(i) == ON) f = -EPS
         end if
         x = rp(i)*fe(i) - f*rp(i)*x
         if (from_start) then
            ai = -ca*vn(i) - cb*an(i)
            vi = vn(i) + DT*((1.0_dp - GAMMA)*an(i) + GAMMA*ai) + cv*x
            ai = ai + cm*x
            ui = un(i) + x
         else
            ui = u(i) + x; vi = v(i) + cv*x; ai = a(i) + cm*x
         end if
         u(i) = ui; v(i) = vi; a(i) = ai
         fi = kg(i)*ui + cg(i)*vi
         if (i < n) then
            pen = ui - u1 - GAP
            b = OFF; f = 0.0_dp
            if (pen > 0.0_dp) then
               b = ON; f = EPS*pen
            end if
            br(i) = b
            if (b /= brf(i)) flipped = .true.
            fi = fi + f; f1 = f1 - f
            fe(i + 1) = f1
         end if
         f1 = fi; u1 = ui
      end do
      fe(1) = f1; fe(0) = 0.0_dp
   end subroutine backward

   !> J = c_m M + K + c_v C on the branches brf, factorised (reciprocal pivots), and the
   !> residual M a + f_int − f_ext at the iterate forward-substituted: fe ← y
   subroutine refactor(n, acc, a, kg, cg, brf, fe, rp, ok)
      integer, intent(in) :: n
      real(dp), intent(in) :: acc, a(0:n), kg(n), cg(n)
      integer(int8), intent(in) :: brf(0:n)
      real(dp), intent(inout) :: fe(0:n)
      real(dp), intent(out) :: rp(n)
      logical, intent(out) :: ok
      real(dp) :: tp, tpm, jo, jom, g, y, p, jd
      integer :: i
      ok = .true.; tpm = 0.0_dp; jom = 0.0_dp; g = 0.0_dp; y = 0.0_dp
      do i = 1, n
         tp = 0.0_dp
         if (i < n) then
            if (brf(i) == ON) tp = EPS
         end if
         jo = -tp
         jd = kg(i) + cv*cg(i) + tpm + tp
         p = cm*M + jd - jom*g
         if (.not. (p > 0.0_dp)) ok = .false.
         rp(i) = 1.0_dp/p
         y = M*(acc - a(i)) - fe(i) - g*y
         g = jo*rp(i)
         fe(i) = y
         tpm = tp; jom = jo
      end do
      fe(0) = 0.0_dp
   end subroutine refactor

end program lean_chain
