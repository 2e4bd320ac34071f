/* fogvol.h for the test programs: with its implementation inline, or, with FOGVOL_TEST_LINKED
   (make test), without it: one object built from tests/fogvol_impl.c per set of compiler flags is
   linked in instead, so that the implementation is compiled twice per `make test` (plain and under
   ASan+UBSan) rather than once per program. */
#ifndef FOGVOL_TEST_H
#define FOGVOL_TEST_H
#ifndef FOGVOL_TEST_LINKED
#define FOGVOL_IMPLEMENTATION
#endif
#include "fogvol.h"
#endif
