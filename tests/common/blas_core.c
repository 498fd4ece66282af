/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * blas_core: print the kernel OpenBLAS chose (openblas_get_corename: the
 * one OPENBLAS_CORETYPE asks for when the library is built for several,
 * else the CPU's), for tests/blas_kernel.sh.
 */
#include <stdio.h>

#include <cblas.h>

int main(void)
{
    const char *name = openblas_get_corename();
    if (!name)
        return 1;
    printf("%s\n", name);
    return 0;
}
