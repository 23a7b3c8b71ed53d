!> The scene as native code sees it: a 1D network of lumped masses (nodes), two-node links,
!> unilateral contacts and loads. Node numbers are 1-based here; 0 means ground. The C door
!> (api_model.f90) converts from the 0-based numbering of the C API. What derives from the
!> whole model (the contacts' effective masses) is martello_effective_mass's.
module martello_model
   use martello_kinds, only: dp
   use martello_status, only: MARTELLO_OK, MARTELLO_ERR_ARGUMENT, out_of_memory, REAL_BYTES, &
      INT_BYTES, FIX_SMALLER_SCENE
   use martello_time_functions, only: time_function_t, tf_is_known, TF_TABLE, NPAR_TF
   use martello_contact_laws, only: NPAR_CONTACT, law_is_known, P_RESTITUTION, P_CLIP
   use martello_links, only: NPAR_LINK, link_is_known, LINK_SPRING, LINK_DASHPOT, LINK_BILINEAR, &
      L_STIFF, L_DAMP, L_YIELD, L_HARDENING
   use martello_parameter_domains, only: link_domain_problem, contact_domain_problem, &
      function_domain_problem
   use martello_registry, only: SCHEME_PENALTY, SCHEME_LAGRANGE, SCHEME_AUGMENTED, &
      SCHEME_RESTITUTION, registry_name
   use martello_element_rows, only: rows_t, rows_init, rows_append, rows_append_pair, row_span, &
      row_pair, row_lo, row_hi, rows_move
   use martello_node_incidence, only: node_incidence_t
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   implicit none
   private
   public :: model_t, model_init, model_set_node, model_add_link, model_add_contact, &
      model_initial_state, model_u0, &
      model_add_mass_coupling, model_add_nodal_force, model_set_ground_acceleration, &
      model_add_link_row, model_add_contact_row, rigid_contacts, &
      model_set_influence, model_influence, model_has_influence, &
      model_add_stiffness_block, stiffness_block_t, model_bandwidth, &
      SCHEME_PENALTY, SCHEME_LAGRANGE, SCHEME_AUGMENTED, &
      SCHEME_RESTITUTION, scheme_name, chain_t, model_add_chain, model_expanded, model_expand_chains, &
      model_nlinks, model_ncontacts, model_link_index, model_contact_index, model_contact_at, &
      model_link_at, model_check_link, model_check_contact

   !> Symmetric stiffness and damping matrices between a set of nodes (a statically condensed
   !> structure, e.g. a planar frame on its lateral DOFs, docs/problems.md P10): internal
   !> force f(node) = k·u(node) + c·v(node), recoverable energy ½ uᵀ k u. Ground is not a
   !> block node: a structure's supports are condensed into k.
   type :: stiffness_block_t
      integer, allocatable :: node(:)
      real(dp), allocatable :: k(:, :), c(:, :)
      logical :: damped = .false.     !< c /= 0
   end type stiffness_block_t

   !> A chain added whole (model_add_chain, docs/c-api.md "Chains"): nodes first … first + n − 1,
   !> node i with a spring k(i) to ground (bilinear with fy(i), rho(i) when given) and, where
   !> c(i) > 0, a dashpot c(i); nodes i and i + 1 in contact through gap(i) (one value when
   !> every gap is the same), one scheme, law and parameter row for all. Held per node (the
   !> methods that take a chain as a whole read these arrays); its links and contacts are the
   !> items numbered link0 + 1 … and contact0 + 1 … (spring then dashpot of each node, in
   !> order), made one by one only on a copy (model_expanded), for the methods that take
   !> items one by one. glink, gcontact: the items added one by one before it.
   type :: chain_t
      integer :: first = 0, n = 0, nlink = 0, ncontact = 0
      integer :: link0 = 0, contact0 = 0, glink = 0, gcontact = 0
      real(dp), allocatable :: k(:), c(:), fy(:), rho(:), gap(:)
      integer :: scheme = 0, law = 0
      real(dp) :: par(NPAR_CONTACT) = 0.0_dp
   end type chain_t

   type :: model_t
      integer :: n = 0
      real(dp), allocatable :: mass(:)
      !> the initial displacements and velocities: no entries while every one is 0 (a large
      !> chain from rest keeps 16 B per node less); read them through model_initial_state
      real(dp), allocatable :: u0(:), v0(:)
      logical, allocatable :: fixed(:)
      ! links
      integer :: nlink = 0
      integer, allocatable :: link_kind(:)
      !> each link's row: its elongation Σ coef·u(node) (a node pair: u_a − u_b), its force f
      !> on the nodes coef·f (martello_element_rows)
      type(rows_t) :: lnk
      real(dp), allocatable :: link_par(:, :)           !< (NPAR_LINK, nlink)
      ! contacts: penetration δ = Σ coef·u(node) − gap over the contact's row (a node pair:
      ! u_a − u_b − gap), a compressive force f acts on the nodes as coef·f (pushes a back, b
      ! forward); rows between plan points of floors: docs/buildings.md
      integer :: ncontact = 0
      type(rows_t) :: con
      integer, allocatable :: con_scheme(:), con_law(:)
      real(dp), allocatable :: con_gap(:), con_par(:, :) !< (NPAR_CONTACT, ncontact)
      !> effective mass 1/(B M⁻¹ Bᵀ) of each contact (+inf if neither side moves), and the
      !> damping derived from a target restitution: set by effective_mass_prepare before a run
      real(dp), allocatable :: con_mstar(:)
      ! off-diagonal mass (consistent bar mass): M(a,b) = M(b,a) += value
      integer :: ncoupling = 0
      integer, allocatable :: mc_a(:), mc_b(:)
      real(dp), allocatable :: mc_value(:)
      ! stiffness blocks (no capacity at model_create: the array grows)
      integer :: nblock = 0
      type(stiffness_block_t), allocatable :: block(:)
      !> chains held per node (model_add_chain; the array grows); nlink and ncontact above
      !> count the items added one by one (model_nlinks, model_ncontacts: all of them)
      integer :: nchain = 0
      type(chain_t), allocatable :: chain(:)
      ! loads: gravity is an acceleration along +u acting on M·ι; ground acceleration loads
      ! −M·ι·ü_g (ι the influence vector, Chopra, Dynamics of Structures §9.4)
      real(dp) :: gravity = 0.0_dp
      !> ι of each node: its motion per unit of the uniform acceleration's (a 3D building's uy
      !> and rz move otherwise than the scene's axis); no entries while every one is 1
      real(dp), allocatable :: influence(:)
      integer :: nforce = 0
      integer, allocatable :: force_node(:)
      type(time_function_t), allocatable :: force_fn(:)
      type(time_function_t) :: ground_accel
      !> which items touch each node: built by the first sub-model taken of the model
      !> (martello_submodel), kept while the model does not grow
      type(node_incidence_t) :: incidence
      character(len=512) :: errmsg = ''
   end type model_t

   ! The chains: fortran/chain/model_chains.f90 (submodule chains)
   interface
      !> Add a chain (chain_t) on nodes first … first + n − 1: k(n) the springs to ground; c(n)
      !> the dashpots (0: none; absent: none), fy(n), rho(n) the bilinear springs' yield force
      !> and hardening (absent: linear springs); gap(n − 1) the contacts between neighbours
      !> (absent: none) with scheme, law and par.
      module subroutine model_add_chain(m, first, n, k, c, fy, rho, gap, scheme, law, par, stat)
         type(model_t), intent(inout) :: m
         integer, intent(in) :: first, n, scheme, law
         real(dp), intent(in) :: k(:), par(NPAR_CONTACT)
         real(dp), intent(in), optional :: c(:), fy(:), rho(:), gap(:)
         integer, intent(out) :: stat
      end subroutine model_add_chain
      !> Links and contacts of the model: added one by one and in chains.
      pure module integer function model_nlinks(m) result(nl)
         type(model_t), intent(in) :: m
      end function model_nlinks
      pure module integer function model_ncontacts(m) result(nc)
         type(model_t), intent(in) :: m
      end function model_ncontacts
      !> The number of link (contact) j added one by one among all the model's links (contacts).
      pure module integer function model_link_index(m, j) result(idx)
         type(model_t), intent(in) :: m
         integer, intent(in) :: j
      end function model_link_index
      pure module integer function model_contact_index(m, j) result(idx)
         type(model_t), intent(in) :: m
         integer, intent(in) :: j
      end function model_contact_index
      !> Link number j of all the model's links: kind, nodes and parameters.
      pure module subroutine model_link_at(m, j, kind, a, b, par)
         type(model_t), intent(in) :: m
         integer, intent(in) :: j
         integer, intent(out) :: kind, a, b
         real(dp), intent(out) :: par(NPAR_LINK)
      end subroutine model_link_at
      !> Contact number j of all the model's contacts: nodes, gap, scheme, law, parameters.
      pure module subroutine model_contact_at(m, j, a, b, gap, scheme, law, par)
         type(model_t), intent(in) :: m
         integer, intent(in) :: j
         integer, intent(out) :: a, b, scheme, law
         real(dp), intent(out) :: gap, par(NPAR_CONTACT)
      end subroutine model_contact_at
      !> The chains made into links and contacts one by one, in place (the model's own copy).
      module subroutine model_expand_chains(m, stat, message)
         type(model_t), intent(inout) :: m
         integer, intent(out) :: stat
         character(len=*), intent(inout) :: message
      end subroutine model_expand_chains
      !> A copy of the model with its chains as links and contacts one by one.
      module subroutine model_expanded(m, copy, stat, message)
         type(model_t), intent(in) :: m
         type(model_t), allocatable, intent(out) :: copy
         integer, intent(out) :: stat
         character(len=*), intent(inout) :: message
      end subroutine model_expanded
   end interface

contains

   !> The scheme's name in the registry (and in scene files).
   pure function scheme_name(scheme) result(name)
      integer, intent(in) :: scheme
      character(len=:), allocatable :: name
      name = registry_name('schemes', scheme)
   end function scheme_name

   subroutine fail(m, stat, msg)
      type(model_t), intent(inout) :: m
      integer, intent(out) :: stat
      character(len=*), intent(in) :: msg
      stat = MARTELLO_ERR_ARGUMENT
      m%errmsg = msg
   end subroutine fail

   !> Allocate for n nodes and the given capacities (the front end knows them up front).
   subroutine model_init(m, n, max_links, max_contacts, max_forces, max_couplings, stat)
      type(model_t), intent(inout) :: m
      integer, intent(in) :: n, max_links, max_contacts, max_forces, max_couplings
      integer, intent(out) :: stat
      character(len=128) :: what
      stat = MARTELLO_OK
      if (n < 1 .or. min(max_links, max_contacts, max_forces, max_couplings) < 0) then
         call fail(m, stat, 'model_create: need n_nodes >= 1 and non-negative capacities')
         return
      end if
      m%n = n
      allocate (m%mass(n), m%u0(0), m%v0(0), m%influence(0), m%fixed(n), &
                m%link_kind(max_links), &
                m%link_par(NPAR_LINK, max_links), &
                m%con_scheme(max_contacts), &
                m%con_law(max_contacts), m%con_gap(max_contacts), &
                m%con_par(NPAR_CONTACT, max_contacts), m%con_mstar(max_contacts), &
                m%force_node(max_forces), m%force_fn(max_forces), &
                m%mc_a(max_couplings), m%mc_b(max_couplings), m%mc_value(max_couplings), stat=stat)
      if (stat /= 0) then
         write (what, '(a,i0,a,i0,a,i0,a)') 'a model of ', n, ' nodes, ', max_links, ' links and ', &
            max_contacts, ' contacts'
         call out_of_memory(trim(what), REAL_BYTES*(real(n, dp) + NPAR_LINK*real(max_links, dp) &
                            + (NPAR_CONTACT + 2.0_dp)*max_contacts + max_couplings) &
                            + INT_BYTES*(2.0_dp*n + 3.0_dp*max_links + 4.0_dp*max_contacts &
                            + max_forces + 2.0_dp*max_couplings) &
                            + storage_size(m%force_fn)/8*real(max_forces, dp), &
                            FIX_SMALLER_SCENE, stat, m%errmsg)
         return
      end if
      if (stat == 0) call rows_init(m%lnk, max_links, 2, stat)
      if (stat == 0) call rows_init(m%con, max_contacts, 2, stat)
      if (stat /= 0) then
         call out_of_memory('the rows of the links and contacts', &
                            (REAL_BYTES + INT_BYTES)*2.0_dp*(real(max_links, dp) + max_contacts), &
                            FIX_SMALLER_SCENE, stat, m%errmsg)
         return
      end if
      m%mass = -1.0_dp; m%fixed = .false.
   end subroutine model_init

   logical function node_ok(m, i, ground_allowed)
      type(model_t), intent(in) :: m
      integer, intent(in) :: i
      logical, intent(in) :: ground_allowed
      node_ok = (i >= 1 .and. i <= m%n) .or. (ground_allowed .and. i == 0)
   end function node_ok

   subroutine model_set_node(m, i, mass, u0, v0, fixed, stat)
      type(model_t), intent(inout) :: m
      integer, intent(in) :: i
      real(dp), intent(in) :: mass, u0, v0
      logical, intent(in) :: fixed
      integer, intent(out) :: stat
      stat = MARTELLO_OK
      if (.not. node_ok(m, i, .false.)) then
         call fail(m, stat, 'set_node: node index out of range'); return
      end if
      if (.not. (ieee_is_finite(mass) .and. ieee_is_finite(u0) .and. ieee_is_finite(v0))) then
         call fail(m, stat, 'set_node: mass, u0 and v0 must be finite'); return
      end if
      ! A fixed node may be massless (a support); a free one needs mass > 0.
      if (mass < 0.0_dp .or. (.not. fixed .and. mass <= 0.0_dp)) then
         call fail(m, stat, 'set_node: mass must be > 0 for a free node (>= 0 for a fixed one)')
         return
      end if
      m%mass(i) = mass; m%fixed(i) = fixed
      call set_initial(m%u0, i, u0); call set_initial(m%v0, i, v0)
   contains
      !> x(i) ← value, x made whole (zeros) by the first value that is not +0
      subroutine set_initial(x, i, value)
         real(dp), allocatable, intent(inout) :: x(:)
         integer, intent(in) :: i
         real(dp), intent(in) :: value
         if (size(x) == 0) then
            if (value == 0.0_dp .and. sign(1.0_dp, value) > 0.0_dp) return
            deallocate (x); allocate (x(m%n), source=0.0_dp)
         end if
         x(i) = value
      end subroutine set_initial
   end subroutine model_set_node

   !> The state at t = 0 (nodes 1..n): u(i) = u0 of node i, v(i) its v0 (0 for a fixed node).
   pure subroutine model_initial_state(m, u, v)
      type(model_t), intent(in) :: m
      real(dp), intent(out) :: u(:), v(:)
      u = 0.0_dp; v = 0.0_dp
      if (size(m%u0) > 0) u = m%u0
      if (size(m%v0) > 0) v = merge(0.0_dp, m%v0, m%fixed)
   end subroutine model_initial_state

   !> u0 of node i (0 where none was given).
   pure real(dp) function model_u0(m, i) result(u0)
      type(model_t), intent(in) :: m
      integer, intent(in) :: i
      u0 = 0.0_dp
      if (size(m%u0) > 0) u0 = m%u0(i)
   end function model_u0

   !> Set the influence vector ι (nodes 1..n): gravity and the ground acceleration load M·ι.
   subroutine model_set_influence(m, iota, stat)
      type(model_t), intent(inout) :: m
      real(dp), intent(in) :: iota(:)
      integer, intent(out) :: stat
      stat = MARTELLO_OK
      if (size(iota) /= m%n) then
         call fail(m, stat, 'set_influence: give one value per node'); return
      end if
      if (.not. all(ieee_is_finite(iota))) then
         call fail(m, stat, 'set_influence: the influence must be finite'); return
      end if
      if (allocated(m%influence)) deallocate (m%influence)
      allocate (m%influence(m%n), stat=stat)
      if (stat /= 0) then
         call out_of_memory('the influence vector', REAL_BYTES*m%n, FIX_SMALLER_SCENE, stat, m%errmsg)
         return
      end if
      m%influence = iota
   end subroutine model_set_influence

   !> ι of node i (1 where none was set).
   pure real(dp) function model_influence(m, i) result(iota)
      type(model_t), intent(in) :: m
      integer, intent(in) :: i
      iota = 1.0_dp
      if (.not. allocated(m%influence)) return
      if (size(m%influence) > 0) iota = m%influence(i)
   end function model_influence

   !> Whether an influence vector was set (else ι = 1 for every node).
   pure logical function model_has_influence(m) result(has)
      type(model_t), intent(in) :: m
      has = .false.
      if (allocated(m%influence)) has = size(m%influence) > 0
   end function model_has_influence

   subroutine model_add_link(m, kind, a, b, par, stat)
      type(model_t), intent(inout) :: m
      integer, intent(in) :: kind, a, b
      real(dp), intent(in) :: par(NPAR_LINK)
      integer, intent(out) :: stat
      call link_room(m, 'add_link', stat)
      if (stat == MARTELLO_OK) call model_check_link(m, kind, a, b, par, stat)
      if (stat == MARTELLO_OK) call append_link(m, kind, [a, b], [1.0_dp, -1.0_dp], par, stat)
   end subroutine model_add_link

   !> Add a link whose elongation is Σ coef(k)·u(node(k)) (node 0: the ground, left out): a
   !> link between plan points of floors (docs/buildings.md), its force f acting as coef·f.
   subroutine model_add_link_row(m, kind, node, coef, par, stat)
      type(model_t), intent(inout) :: m
      integer, intent(in) :: kind, node(:)
      real(dp), intent(in) :: coef(:), par(NPAR_LINK)
      integer, intent(out) :: stat
      call link_room(m, 'add_link_row', stat)
      if (stat == MARTELLO_OK) call check_row(m, 'add_link_row', node, coef, stat)
      if (stat == MARTELLO_OK) call model_check_link(m, kind, 0, -1, par, stat)
      if (stat == MARTELLO_OK) call append_link(m, kind, node, coef, par, stat)
   end subroutine model_add_link_row

   !> Room for one more link (the capacity of model_create).
   subroutine link_room(m, what, stat)
      type(model_t), intent(inout) :: m
      character(len=*), intent(in) :: what
      integer, intent(out) :: stat
      stat = MARTELLO_OK
      if (m%nlink >= size(m%link_kind)) call fail(m, stat, what//': more links than declared at model_create')
   end subroutine link_room

   !> A checked link appended: its row, kind and parameters.
   subroutine append_link(m, kind, node, coef, par, stat)
      type(model_t), intent(inout) :: m
      integer, intent(in) :: kind, node(:)
      real(dp), intent(in) :: coef(:), par(NPAR_LINK)
      integer, intent(out) :: stat
      call rows_append(m%lnk, node, coef, stat)
      if (stat /= 0) then
         call out_of_memory('a link row', (REAL_BYTES + INT_BYTES)*size(node), FIX_SMALLER_SCENE, &
                            stat, m%errmsg)
         return
      end if
      m%nlink = m%nlink + 1
      m%link_kind(m%nlink) = kind
      m%link_par(:, m%nlink) = par
   end subroutine append_link

   !> What a row needs: nodes of the model or 0 (the ground), finite coefficients, at least
   !> one term on a node.
   subroutine check_row(m, what, node, coef, stat)
      type(model_t), intent(inout) :: m
      character(len=*), intent(in) :: what
      integer, intent(in) :: node(:)
      real(dp), intent(in) :: coef(:)
      integer, intent(out) :: stat
      integer :: k
      stat = MARTELLO_OK
      if (size(node) /= size(coef)) then
         call fail(m, stat, what//': as many coefficients as nodes'); return
      end if
      do k = 1, size(node)
         if (.not. node_ok(m, node(k), .true.)) then
            call fail(m, stat, what//': node out of range'); return
         end if
      end do
      if (.not. all(ieee_is_finite(coef))) then
         call fail(m, stat, what//': coefficients must be finite'); return
      end if
      if (.not. any(node > 0 .and. coef /= 0.0_dp)) then
         call fail(m, stat, what//': the row has no term on a node (it joins nothing that moves)')
      end if
   end subroutine check_row

   !> What add_link checks of one link (its nodes, kind and parameters; b = −1: a row's link,
   !> its nodes checked by check_row); a chain's links too.
   subroutine model_check_link(m, kind, a, b, par, stat)
      type(model_t), intent(inout) :: m
      integer, intent(in) :: kind, a, b
      real(dp), intent(in) :: par(NPAR_LINK)
      integer, intent(out) :: stat
      stat = MARTELLO_OK
      if (.not. link_is_known(kind)) then
         call fail(m, stat, 'add_link: unknown link kind'); return
      end if
      if (b /= -1) then       ! b = −1: a row's link, its nodes checked by check_row
         if (.not. (node_ok(m, a, .true.) .and. node_ok(m, b, .true.)) .or. a == b) then
            call fail(m, stat, 'add_link: nodes out of range, or both ends on the same node'); return
         end if
      end if
      if (.not. all(ieee_is_finite(par))) then
         call fail(m, stat, 'add_link: parameters must be finite'); return
      end if
      call fail_unless_empty(m, stat, 'add_link: ', link_domain_problem(kind, par))
   end subroutine model_check_link

   !> fail with prefix//problem unless problem is '' (martello_parameter_domains).
   subroutine fail_unless_empty(m, stat, prefix, problem)
      type(model_t), intent(inout) :: m
      integer, intent(inout) :: stat
      character(len=*), intent(in) :: prefix, problem
      if (len(problem) > 0) call fail(m, stat, prefix//problem)
   end subroutine fail_unless_empty

   subroutine model_add_contact(m, a, b, gap, scheme, law, par, stat)
      type(model_t), intent(inout) :: m
      integer, intent(in) :: a, b, scheme, law
      real(dp), intent(in) :: gap, par(NPAR_CONTACT)
      integer, intent(out) :: stat
      call contact_room(m, 'add_contact', stat)
      if (stat == MARTELLO_OK) call model_check_contact(m, a, b, gap, scheme, law, par, stat)
      if (stat == MARTELLO_OK) call append_contact(m, [a, b], [1.0_dp, -1.0_dp], gap, scheme, law, &
                                                   par, stat)
   end subroutine model_add_contact

   !> Add a contact whose penetration is Σ coef(k)·u(node(k)) − gap (node 0: the ground, left
   !> out): a contact between plan points of floors (docs/buildings.md), its compressive force
   !> f acting as coef·f on the nodes.
   subroutine model_add_contact_row(m, node, coef, gap, scheme, law, par, stat)
      type(model_t), intent(inout) :: m
      integer, intent(in) :: node(:), scheme, law
      real(dp), intent(in) :: coef(:), gap, par(NPAR_CONTACT)
      integer, intent(out) :: stat
      call contact_room(m, 'add_contact_row', stat)
      if (stat == MARTELLO_OK) call check_row(m, 'add_contact_row', node, coef, stat)
      if (stat == MARTELLO_OK) call model_check_contact(m, 0, -1, gap, scheme, law, par, stat)
      if (stat == MARTELLO_OK) call append_contact(m, node, coef, gap, scheme, law, par, stat)
   end subroutine model_add_contact_row

   !> Room for one more contact (the capacity of model_create).
   subroutine contact_room(m, what, stat)
      type(model_t), intent(inout) :: m
      character(len=*), intent(in) :: what
      integer, intent(out) :: stat
      stat = MARTELLO_OK
      if (m%ncontact >= size(m%con_scheme)) &
         call fail(m, stat, what//': more contacts than declared at model_create')
   end subroutine contact_room

   !> A checked contact appended: its row, gap, scheme, law and parameters.
   subroutine append_contact(m, node, coef, gap, scheme, law, par, stat)
      type(model_t), intent(inout) :: m
      integer, intent(in) :: node(:), scheme, law
      real(dp), intent(in) :: coef(:), gap, par(NPAR_CONTACT)
      integer, intent(out) :: stat
      call rows_append(m%con, node, coef, stat)
      if (stat /= 0) then
         call out_of_memory('a contact row', (REAL_BYTES + INT_BYTES)*size(node), FIX_SMALLER_SCENE, &
                            stat, m%errmsg)
         return
      end if
      m%ncontact = m%ncontact + 1
      m%con_gap(m%ncontact) = gap
      m%con_scheme(m%ncontact) = scheme; m%con_law(m%ncontact) = law
      m%con_par(:, m%ncontact) = par
      m%con_mstar(m%ncontact) = 0.0_dp
   end subroutine append_contact

   !> What add_contact checks of one contact (its nodes, scheme, law and parameters; b = −1:
   !> a row's contact, its nodes checked by check_row); a chain's contacts too.
   subroutine model_check_contact(m, a, b, gap, scheme, law, par, stat)
      type(model_t), intent(inout) :: m
      integer, intent(in) :: a, b, scheme, law
      real(dp), intent(in) :: gap, par(NPAR_CONTACT)
      integer, intent(out) :: stat
      stat = MARTELLO_OK
      if (b /= -1) then
         if (.not. (node_ok(m, a, .true.) .and. node_ok(m, b, .true.)) .or. a == b) then
            call fail(m, stat, 'add_contact: nodes out of range, or both sides on the same node')
            return
         end if
      end if
      if (scheme < SCHEME_PENALTY .or. scheme > SCHEME_RESTITUTION) then
         call fail(m, stat, 'add_contact: unknown scheme'); return
      end if
      if (scheme == SCHEME_PENALTY .and. .not. law_is_known(law)) then
         call fail(m, stat, 'add_contact: unknown contact law'); return
      end if
      if (.not. (ieee_is_finite(gap) .and. all(ieee_is_finite(par)))) then
         call fail(m, stat, 'add_contact: gap and parameters must be finite'); return
      end if
      if (any(par(P_CLIP + 1:) /= 0.0_dp)) then
         call fail(m, stat, 'add_contact: par[5] and above are reserved and must be 0 (the'// &
                   ' effective mass m* is computed by the library from the masses)'); return
      end if
      call fail_unless_empty(m, stat, 'add_contact: ', contact_domain_problem(scheme, law, par))
   end subroutine model_check_contact

   subroutine model_add_mass_coupling(m, a, b, value, stat)
      type(model_t), intent(inout) :: m
      integer, intent(in) :: a, b
      real(dp), intent(in) :: value
      integer, intent(out) :: stat
      stat = MARTELLO_OK
      if (m%ncoupling >= size(m%mc_a)) then
         call fail(m, stat, 'add_mass_coupling: more couplings than declared'); return
      end if
      if (.not. (node_ok(m, a, .false.) .and. node_ok(m, b, .false.)) .or. a == b &
          .or. .not. ieee_is_finite(value)) then
         call fail(m, stat, 'add_mass_coupling: two distinct nodes and a finite value needed')
         return
      end if
      m%ncoupling = m%ncoupling + 1
      m%mc_a(m%ncoupling) = a; m%mc_b(m%ncoupling) = b; m%mc_value(m%ncoupling) = value
   end subroutine model_add_mass_coupling

   !> Add the symmetric stiffness block k and damping block c (nb × nb) between the distinct
   !> nodes node(1:nb). Both must be exactly symmetric (the caller symmetrises), k with a
   !> positive diagonal, c with a non-negative one; positive semi-definiteness is the
   !> caller's (a condensed stiffness and a Rayleigh damping are).
   subroutine model_add_stiffness_block(m, node, k, c, stat)
      type(model_t), intent(inout) :: m
      integer, intent(in) :: node(:)
      real(dp), intent(in) :: k(:, :), c(:, :)
      integer, intent(out) :: stat
      type(stiffness_block_t), allocatable :: grown(:)
      integer :: i, nb
      character(len=64) :: what
      stat = MARTELLO_OK
      nb = size(node)
      if (nb < 1 .or. size(k, 1) /= nb .or. size(k, 2) /= nb .or. size(c, 1) /= nb .or. &
          size(c, 2) /= nb) then
         call fail(m, stat, 'add_stiffness_block: need n >= 1 nodes and n x n matrices'); return
      end if
      do i = 1, nb
         if (.not. node_ok(m, node(i), .false.)) then
            call fail(m, stat, 'add_stiffness_block: node out of range (ground is not a block'// &
                      ' node: condense the supports into k)'); return
         end if
         if (any(node(:i - 1) == node(i))) then
            call fail(m, stat, 'add_stiffness_block: a node appears twice'); return
         end if
      end do
      if (.not. (all(ieee_is_finite(k)) .and. all(ieee_is_finite(c)))) then
         call fail(m, stat, 'add_stiffness_block: k and c must be finite'); return
      end if
      if (any(k /= transpose(k)) .or. any(c /= transpose(c))) then
         call fail(m, stat, 'add_stiffness_block: k and c must be symmetric (give (k + kT)/2)')
         return
      end if
      do i = 1, nb
         if (.not. (k(i, i) > 0.0_dp .and. c(i, i) >= 0.0_dp)) then
            call fail(m, stat, 'add_stiffness_block: the diagonal of k must be > 0, of c >= 0')
            return
         end if
      end do
      allocate (grown(m%nblock + 1), stat=stat)
      if (stat == 0) allocate (grown(m%nblock + 1)%node(nb), grown(m%nblock + 1)%k(nb, nb), &
                               grown(m%nblock + 1)%c(nb, nb), stat=stat)
      if (stat /= 0) then
         write (what, '(a,i0,a)') 'a stiffness block of ', nb, ' nodes'
         call out_of_memory(trim(what), 2*REAL_BYTES*nb*real(nb, dp) + INT_BYTES*nb, &
                            FIX_SMALLER_SCENE, stat, m%errmsg)
         return
      end if
      do i = 1, m%nblock
         call move_alloc(m%block(i)%node, grown(i)%node)
         call move_alloc(m%block(i)%k, grown(i)%k)
         call move_alloc(m%block(i)%c, grown(i)%c)
         grown(i)%damped = m%block(i)%damped
      end do
      grown(m%nblock + 1)%node = node
      grown(m%nblock + 1)%k = k
      grown(m%nblock + 1)%c = c
      grown(m%nblock + 1)%damped = any(c /= 0.0_dp)
      call move_alloc(grown, m%block)
      m%nblock = m%nblock + 1
   end subroutine model_add_stiffness_block

   subroutine set_function(m, fn, kind, par, t, y, stat)
      type(model_t), intent(inout) :: m
      type(time_function_t), intent(out) :: fn
      integer, intent(in) :: kind
      real(dp), intent(in) :: par(NPAR_TF), t(:), y(:)
      integer, intent(out) :: stat
      integer :: i
      stat = MARTELLO_OK
      if (.not. tf_is_known(kind)) then
         call fail(m, stat, 'time function: unknown kind'); return
      end if
      if (.not. (all(ieee_is_finite(par)) .and. all(ieee_is_finite(t)) .and. &
                 all(ieee_is_finite(y)))) then
         call fail(m, stat, 'time function: values must be finite'); return
      end if
      call fail_unless_empty(m, stat, 'time function: ', function_domain_problem(kind, par))
      if (stat /= MARTELLO_OK) return
      if (kind == TF_TABLE) then
         if (size(t) < 2 .or. size(t) /= size(y)) then
            call fail(m, stat, 'time function: a table needs >= 2 (t, y) pairs'); return
         end if
         do i = 2, size(t)
            if (t(i) <= t(i - 1)) then
               call fail(m, stat, 'time function: table times must increase strictly'); return
            end if
         end do
         fn%t = t; fn%y = y
      end if
      fn%kind = kind; fn%par = par
   end subroutine set_function

   subroutine model_add_nodal_force(m, node, kind, par, t, y, stat)
      type(model_t), intent(inout) :: m
      integer, intent(in) :: node, kind
      real(dp), intent(in) :: par(NPAR_TF), t(:), y(:)
      integer, intent(out) :: stat
      stat = MARTELLO_OK
      if (m%nforce >= size(m%force_node)) then
         call fail(m, stat, 'add_nodal_force: more forces than declared'); return
      end if
      if (.not. node_ok(m, node, .false.)) then
         call fail(m, stat, 'add_nodal_force: node out of range'); return
      end if
      call set_function(m, m%force_fn(m%nforce + 1), kind, par, t, y, stat)
      if (stat /= MARTELLO_OK) return
      m%nforce = m%nforce + 1
      m%force_node(m%nforce) = node
   end subroutine model_add_nodal_force

   subroutine model_set_ground_acceleration(m, kind, par, t, y, stat)
      type(model_t), intent(inout) :: m
      integer, intent(in) :: kind
      real(dp), intent(in) :: par(NPAR_TF), t(:), y(:)
      integer, intent(out) :: stat
      call set_function(m, m%ground_accel, kind, par, t, y, stat)
   end subroutine model_set_ground_acceleration

   !> Half-bandwidth of the mass, stiffness and contact matrices: max |a − b| over every
   !> two-node element (ground ends do not count) and every stiffness block's node span.
   !> 1 for chains numbered in order.
   pure integer function model_bandwidth(m) result(kd)
      type(model_t), intent(in) :: m
      integer :: j
      kd = 0
      do j = 1, m%nlink
         kd = max(kd, row_span(m%lnk, j))
      end do
      do j = 1, m%ncontact
         kd = max(kd, row_span(m%con, j))
      end do
      do j = 1, m%ncoupling
         kd = max(kd, abs(m%mc_a(j) - m%mc_b(j)))
      end do
      do j = 1, m%nblock
         kd = max(kd, maxval(m%block(j)%node) - minval(m%block(j)%node))
      end do
      do j = 1, m%nchain
         if (m%chain(j)%ncontact > 0) kd = max(kd, 1)
      end do
   end function model_bandwidth

   !> For the impulse-level integrators: which contacts are rigid (restitution or Lagrange,
   !> solved by complementarity), their restitution (Lagrange without one: 0, plastic), and
   !> which can move — a rigid contact with a term on a free node (terms on a fixed node do not
   !> move: the Delassus operator leaves them out).
   pure subroutine rigid_contacts(m, rigid, e, movable)
      type(model_t), intent(in) :: m
      logical, intent(out) :: rigid(:), movable(:)
      real(dp), intent(out) :: e(:)
      integer :: c, k
      do c = 1, m%ncontact
         rigid(c) = m%con_scheme(c) /= SCHEME_PENALTY
         e(c) = max(m%con_par(P_RESTITUTION, c), 0.0_dp)
         movable(c) = .false.
         do k = row_lo(m%con, c), row_hi(m%con, c)
            if (.not. m%fixed(m%con%node(k)) .and. m%con%coef(k) /= 0.0_dp) movable(c) = rigid(c)
         end do
      end do
   end subroutine rigid_contacts
end module martello_model
