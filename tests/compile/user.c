/* Translation unit that only includes the declarations and calls the API. */
#include "fogvol.h"
#include <stdio.h>
int main(void)
{
    fogvol_encoding e;
    unsigned char px[4];
    if (fogvol_encoding_init(4, &e) != FOGVOL_SUCCESS) return 1;
    if (fogvol_encode_depth(&e, 0.5, 0, px) != FOGVOL_SUCCESS || px[0] != 8) return 1;
    printf("%s\n", fogvol_result_string(FOGVOL_SUCCESS));
    return 0;
}
