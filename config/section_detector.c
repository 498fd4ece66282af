/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * section_detector.c: the detector: section of a site file, what
 * commissioning (amfi-commission, docs/commissioning.md) found of the
 * vehicle detector against the accelerometers: its clock offset (detector
 * time − true time, s) and its speed scale (reported / true speed; the
 * spacings, measured from the speed, alike). amfi-solve and amfid correct
 * every vehicle with them, both by amfi_config_detector_correct(). The table runs
 * on the loader's thread; amfi_config_detector_correct is pure (any thread).
 */
#include <math.h>

#include "sections.h"

const field amfi_cfg_detector_fields[] = {
    /* live: a commissioning result applies from the next vehicle on */
    AMFI_CFG_DETECTOR_ROWS(offsetof(amfi_site_config, detector), F_LIVE),
    {.key = NULL}};

void amfi_config_detector_correct(const amfi_detector_config *d, double *entry_s, int64_t *utime,
                           double *speed_mps, double *spacing_m, int n_spacings)
{
    if (entry_s)
        *entry_s -= d->clock_offset_s;
    if (utime)
        *utime -= (int64_t)llround(1e6 * d->clock_offset_s);
    if (speed_mps)
        *speed_mps /= d->speed_scale;
    for (int k = 0; k < n_spacings; k++)
        spacing_m[k] /= d->speed_scale;
}
