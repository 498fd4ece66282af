/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * sweep.c: the sweep dispatcher: one backward/forward sweep in the solver's
 * coordinates (modal or nodal). Called by solver.c and lcurve.c; calls only
 * the two sweeps, which never call back.
 */
#include "solver_internal.h"

int amfi_sweep(struct amfi_solver *s, double lam, double *res_norm, double *smo_norm)
{
    if (s->p.coords == AMFI_COORDS_NODAL)
        return amfi_sweep_nodal(s, lam, res_norm, smo_norm);
    return amfi_sweep_modal(s, lam, res_norm, smo_norm);
}
