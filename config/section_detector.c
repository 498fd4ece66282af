/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * section_detector.c: the detector: section of a site file, what
 * commissioning (amfi-commission, docs/commissioning.md) found of the
 * vehicle detector against the accelerometers: its clock offset (detector
 * time − true time, s) and its speed scale (reported / true speed; the
 * spacings, measured from the speed, alike). amfi-solve and amfid correct
 * every vehicle with them. Runs on the loader's thread.
 */
#include "sections.h"

const field amfi_cfg_detector_fields[] = {
    AMFI_CFG_DETECTOR_ROWS(offsetof(amfi_site_config, detector)),
    {.key = NULL}};
