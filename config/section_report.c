/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * section_report.c: the report: section of a site file, what amfi-report
 * (--config FILE) holds passages against: the legal gross vehicle weight
 * and axle load for --overloads (report.limits.gvw_kg, report.limits.axle_kg),
 * the bin width of --histogram (report.histogram_bin_kg) and the units of
 * its tables and plots (report.units). The defaults
 * (amfi_config_defaults) are EU Directive 96/53/EC, Annex I: 40 t for a
 * vehicle combination (2.2.2), 11.5 t for a driving axle (3.2). amfid
 * reads the section but does not use it. Runs on the loader's thread.
 */
#include "sections.h"

#define REP(m) offsetof(amfi_site_config, report.m)

static const field limit_fields[] = {
    {.key = "gvw_kg", .kind = &amfi_cfg_k_double, .off = REP(gvw_limit_kg), .lo = 0, .hi = 1e6,
     .flags = F_LO_OPEN},
    {.key = "axle_kg", .kind = &amfi_cfg_k_double, .off = REP(axle_limit_kg), .lo = 0, .hi = 1e6,
     .flags = F_LO_OPEN},
    {.key = NULL}};

static const enum_name unit_names[] = {{"si", AMFI_REPORT_UNITS_SI},
                                       {"engineering", AMFI_REPORT_UNITS_ENGINEERING},
                                       {NULL, 0}};

const field amfi_cfg_report_fields[] = {
    {.key = "limits", .kind = &amfi_cfg_k_map, .aux = limit_fields},
    {.key = "histogram_bin_kg", .kind = &amfi_cfg_k_double, .off = REP(bin_kg), .lo = 100, .hi = 1e5},
    {.key = "units", .kind = &amfi_cfg_k_enum, .off = REP(units), .aux = unit_names},
    {.key = NULL}};
