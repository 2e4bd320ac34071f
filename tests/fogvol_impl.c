/* The implementation of fogvol.h as an object of its own, which `make test` builds once per set
   of compiler flags and links into the test programs built with FOGVOL_TEST_LINKED
   (tests/fogvol_test.h). */
#define FOGVOL_IMPLEMENTATION
#include "fogvol.h"
