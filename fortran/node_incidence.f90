!> Which items of a model touch each node, in CSR form: the elements (links, contacts, mass
!> couplings, stiffness blocks) and the nodal forces. A model keeps one (model_t%incidence),
!> built on the first sub-model taken of it (martello_submodel) and rebuilt only when the model
!> has grown since, so that a sub-model of c nodes costs O(c + the items they touch), not O(n)
!> (docs/run-layer.md, "Sub-models for local stepping").
module martello_node_incidence
   implicit none
   private
   public :: node_incidence_t, INCIDENCE_KEYS

   !> what an incidence is built for: nodes, links, contacts, couplings, blocks, forces and the
   !> terms of the links' and contacts' rows
   integer, parameter :: INCIDENCE_KEYS = 8

   type :: node_incidence_t
      !> the model's sizes when built (−1: never built)
      integer :: built_for(INCIDENCE_KEYS) = -1
      !> elements of node i: elem(efirst(i) … efirst(i + 1) − 1), ascending; an element is
      !> numbered links 1 … nlink, then the contacts, the couplings and the blocks in turn
      integer, allocatable :: efirst(:), elem(:)
      !> nodal forces of node i: force(ffirst(i) … ffirst(i + 1) − 1), ascending
      integer, allocatable :: ffirst(:), force(:)
      !> scratch of a sub-model's construction, all 0 between constructions: per element, per
      !> node (so that marking costs nothing to clear)
      integer, allocatable :: elem_mark(:), node_mark(:)
   end type node_incidence_t
end module martello_node_incidence
