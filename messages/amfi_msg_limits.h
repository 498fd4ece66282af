/* SPDX-License-Identifier: GPL-3.0-or-later */
/* amfi_msg_limits.h: the limits of the amfi bus message types, in one place
 * (docs/messages.md, "Limits"). The raw-buffer checker (amfi_msg_check.h)
 * refuses a message whose count or string exceeds them before lcm-gen's
 * decoder sees it. messages/gen_msg_check.cmake refers to one macro per
 * dynamic array count, AMFI_MSG_MAX_<TYPE>_<COUNTFIELD> (elements), and one per
 * string, AMFI_MSG_MAX_<TYPE>_<FIELD> (bytes without the terminating NUL),
 * TYPE being the type name without "_t" in upper case: a new array or string
 * field in a .lcm file does not compile until its limit is added here.
 */
#ifndef AMFI_MSG_LIMITS_H
#define AMFI_MSG_LIMITS_H

/* Limits stated in the .lcm comments. */
#define AMFI_ACCEL_BLOCK_MAX_SAMPLES 160 /* accel_block_t.n: 1 .. 160, one UDP datagram */
#define AMFI_SENSOR_ID_MAX           255 /* accel_block_t.sensor_id: 0 .. 255 */
#define AMFI_MAX_AXLES               12  /* vehicle_t.n_axles: 1 .. 12 (also amfi/amfi.h) */

/* Short strings that name a state or a kind, and free text. */
#define AMFI_MSG_MAX_NAME 63   /* bytes: status, state, level, kind, formulation */
#define AMFI_MSG_MAX_TEXT 1023 /* bytes: reasons, messages, errors, sources */

/* Array counts (elements). The lower bounds (n >= 1, n_axles >= 1) are the
 * handlers' checks: a zero count decodes safely. */
#define AMFI_MSG_MAX_ACCEL_BLOCK_N        AMFI_ACCEL_BLOCK_MAX_SAMPLES
#define AMFI_MSG_MAX_VEHICLE_N_SPACINGS   (AMFI_MAX_AXLES - 1)
#define AMFI_MSG_MAX_TRUTH_N_AXLES        AMFI_MAX_AXLES
#define AMFI_MSG_MAX_PASSAGE_N_AXLES      AMFI_MAX_AXLES
#define AMFI_MSG_MAX_PASSAGE_N_GROUPS     AMFI_MAX_AXLES

/* Strings (bytes, without the NUL). */
#define AMFI_MSG_MAX_VEHICLE_SOURCE       255
#define AMFI_MSG_MAX_PASSAGE_STATUS       AMFI_MSG_MAX_NAME
#define AMFI_MSG_MAX_PASSAGE_REASON       AMFI_MSG_MAX_TEXT
#define AMFI_MSG_MAX_PASSAGE_FORMULATION  AMFI_MSG_MAX_NAME
#define AMFI_MSG_MAX_PASSAGE_VEHICLE_CLASS 15 /* AMFI_CLASS_NAME_LEN - 1 */
#define AMFI_MSG_MAX_PASSAGE_LOADS_REFUSED 111 /* amfi_classification.loads_why - 1 */
#define AMFI_MSG_MAX_INDICATOR_STATE      AMFI_MSG_MAX_NAME
#define AMFI_MSG_MAX_ALERT_LEVEL          AMFI_MSG_MAX_NAME
#define AMFI_MSG_MAX_ALERT_KIND           AMFI_MSG_MAX_NAME
#define AMFI_MSG_MAX_ALERT_MESSAGE        AMFI_MSG_MAX_TEXT
#define AMFI_MSG_MAX_STATUS_STATE         AMFI_MSG_MAX_NAME
#define AMFI_MSG_MAX_STATUS_LAST_ERROR    AMFI_MSG_MAX_TEXT
#define AMFI_MSG_MAX_SITE_ID              63 /* site.id: [A-Za-z0-9_.-] */
#define AMFI_MSG_MAX_PASSAGE_SITE_ID      AMFI_MSG_MAX_SITE_ID
#define AMFI_MSG_MAX_INDICATOR_SITE_ID    AMFI_MSG_MAX_SITE_ID
#define AMFI_MSG_MAX_ALERT_SITE_ID        AMFI_MSG_MAX_SITE_ID
#define AMFI_MSG_MAX_STATUS_SITE_ID       AMFI_MSG_MAX_SITE_ID

#endif /* AMFI_MSG_LIMITS_H */
