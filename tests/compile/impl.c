/* Translation unit holding the implementation (two-TU build). */
#define FOGVOL_IMPLEMENTATION
#include "fogvol.h"
