/* One translation unit with the implementation (also used in static mode). */
#define FOGVOL_IMPLEMENTATION
#include "fogvol.h"
int main(void)
{
    fogvol_encoding e;
    return fogvol_encoding_init(5, &e) == FOGVOL_SUCCESS && e.max_faces == 8 ? 0 : 1;
}
