/* Linked into the C examples of a MARTELLO_FPE_TRAP build (CMakeLists.txt, scripts/fpe-trap):
 * turns on the traps a Fortran main program gets from -ffpe-trap, before main runs, so an
 * invalid operation, a division by zero or an overflow in the library is a SIGFPE. */
#define _GNU_SOURCE
#include <fenv.h>

__attribute__((constructor)) static void martello_fpe_trap_on(void) {
  feenableexcept(FE_INVALID | FE_DIVBYZERO | FE_OVERFLOW);
}
