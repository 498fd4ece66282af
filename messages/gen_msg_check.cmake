# SPDX-License-Identifier: GPL-3.0-or-later
# gen_msg_check.cmake: generates the field tables of the raw-buffer checker
# (amfi_msg_check.c) from the messages/*.lcm files, at build time, so that a
# field added to a .lcm file cannot be forgotten by the checker.
#
#   cmake -DSRC_DIR=messages -DTYPES="accel_block_t|vehicle_t|..." \
#         -DOUT_DIR=build/messages/c/amfi -P gen_msg_check.cmake
#
# Writes OUT_DIR/amfi_msg_types.h (enum amfi_msg_type, one typed
# amfi_msg_decode_TYPE() per type) and OUT_DIR/amfi_msg_fields.c (the field
# list of each type, its fingerprint and decode/cleanup functions from
# lcm-gen). Every dynamic array refers to the limit macro
# AMFI_MSG_MAX_<TYPE>_<COUNTFIELD> and every string to
# AMFI_MSG_MAX_<TYPE>_<FIELD> (TYPE without "_t", upper case), defined in
# messages/amfi_msg_limits.h: a new array or string without a limit there does
# not compile. Only what amfi's types use is supported (primitive fields,
# strings, one-dimensional arrays with a constant or field dimension); anything
# else (nested types, constants, multi-dimensional arrays) stops the build with
# a message naming the file.
if(NOT SRC_DIR OR NOT TYPES OR NOT OUT_DIR)
  message(FATAL_ERROR "gen_msg_check.cmake: SRC_DIR, TYPES and OUT_DIR are required")
endif()
string(REPLACE "|" ";" TYPES "${TYPES}")

set(sizes_int8_t 1)
set(sizes_int16_t 2)
set(sizes_int32_t 4)
set(sizes_int64_t 8)
set(sizes_float 4)
set(sizes_double 8)
set(sizes_boolean 1)
set(sizes_byte 1)
set(kind_int8_t AMFI_MSG_F_INT8)
set(kind_int16_t AMFI_MSG_F_INT16)
set(kind_int32_t AMFI_MSG_F_INT32)
set(kind_int64_t AMFI_MSG_F_INT64)
set(kind_float AMFI_MSG_F_FLOAT)
set(kind_double AMFI_MSG_F_DOUBLE)
set(kind_boolean AMFI_MSG_F_BOOLEAN)
set(kind_byte AMFI_MSG_F_BYTE)
set(kind_string AMFI_MSG_F_STRING)

set(enum_lines "")
set(each_lines "")
set(decl_lines "")
set(c_body "")
set(desc_lines "")
foreach(t IN LISTS TYPES)
  set(file ${SRC_DIR}/${t}.lcm)
  file(READ ${file} text)
  # Comments out (// to end of line, /* ... */), then one statement per ';'.
  string(REGEX REPLACE "//[^\n]*" "" text "${text}")
  string(REGEX REPLACE "/\\*([^*]|\\*+[^*/])*\\*+/" "" text "${text}")
  if(NOT text MATCHES "package[ \t\r\n]+([A-Za-z0-9_]+)[ \t\r\n]*;")
    message(FATAL_ERROR "${file}: no package statement")
  endif()
  set(pkg ${CMAKE_MATCH_1})
  if(NOT text MATCHES "struct[ \t\r\n]+([A-Za-z0-9_]+)[ \t\r\n]*{([^}]*)}")
    message(FATAL_ERROR "${file}: no struct")
  endif()
  if(NOT CMAKE_MATCH_1 STREQUAL t)
    message(FATAL_ERROR "${file}: struct ${CMAKE_MATCH_1}, expected ${t}")
  endif()
  set(body "${CMAKE_MATCH_2}")
  string(REPLACE "\n" " " body "${body}")
  string(REPLACE "\r" " " body "${body}")
  string(REPLACE "\t" " " body "${body}")
  string(REPLACE ";" "\n" body "${body}")
  string(REGEX REPLACE "\n" ";" stmts "${body}")

  string(TOUPPER ${t} T_UP)
  string(REGEX REPLACE "_T$" "" T_SHORT ${T_UP})
  set(ctype "${pkg}_${t}")
  set(enum_lines "${enum_lines}    AMFI_MSG_${T_UP}, /* ${pkg}.${t}, ${t}.lcm */\n")
  set(each_lines "${each_lines} \\\n    X(AMFI_MSG_${T_UP}, ${t})")
  set(decl_lines "${decl_lines}int amfi_msg_decode_${t}(const void *buf, size_t len, ${ctype} *msg, char *why,\n        size_t whylen);\n")

  set(names "")
  set(rows "")
  set(nf 0)
  foreach(s IN LISTS stmts)
    string(STRIP "${s}" s)
    if(s STREQUAL "")
      continue()
    endif()
    if(s MATCHES "^const[ ]")
      message(FATAL_ERROR "${file}: '${s}': constants are not supported by gen_msg_check.cmake")
    endif()
    if(NOT s MATCHES "^([A-Za-z0-9_.]+) +([A-Za-z_][A-Za-z0-9_]*) *(\\[ *([A-Za-z0-9_]+) *\\])? *$")
      message(FATAL_ERROR "${file}: '${s}': not a field gen_msg_check.cmake understands (one-dimensional arrays only)")
    endif()
    set(ftype ${CMAKE_MATCH_1})
    set(fname ${CMAKE_MATCH_2})
    set(fdim "${CMAKE_MATCH_4}")
    if(NOT DEFINED kind_${ftype})
      message(FATAL_ERROR "${file}: field ${fname}: type ${ftype} is not supported by gen_msg_check.cmake")
    endif()
    string(TOUPPER ${fname} F_UP)
    set(dim_idx -1)
    set(dim_const 0)
    set(max 0)
    if(ftype STREQUAL "string")
      set(max "AMFI_MSG_MAX_${T_SHORT}_${F_UP}")
    endif()
    if(NOT fdim STREQUAL "")
      if(fdim MATCHES "^[0-9]+$")
        set(dim_const ${fdim})
      else()
        list(FIND names ${fdim} dim_idx)
        if(dim_idx LESS 0)
          message(FATAL_ERROR "${file}: ${fname}[${fdim}]: ${fdim} is not an earlier field")
        endif()
        list(GET types_${t} ${dim_idx} dtype)
        if(NOT dtype MATCHES "^int(8|16|32|64)_t$")
          message(FATAL_ERROR "${file}: ${fname}[${fdim}]: ${fdim} is not an integer field")
        endif()
        string(TOUPPER ${fdim} D_UP)
        if(ftype STREQUAL "string")
          # An array of strings: both limits apply, the count's and each string's.
          set(max "AMFI_MSG_MAX_${T_SHORT}_${F_UP}")
        endif()
        set(cmax "AMFI_MSG_MAX_${T_SHORT}_${D_UP}")
      endif()
    endif()
    if(NOT fdim STREQUAL "" AND NOT fdim MATCHES "^[0-9]+$")
      set(countmax ${cmax})
    else()
      set(countmax 0)
    endif()
    list(APPEND names ${fname})
    list(APPEND types_${t} ${ftype})
    set(rows "${rows}    {\"${fname}\", ${kind_${ftype}}, ${dim_idx}, ${dim_const}, ${countmax}, ${max}},\n")
    math(EXPR nf "${nf} + 1")
  endforeach()
  if(nf EQUAL 0 OR nf GREATER 64)
    message(FATAL_ERROR "${file}: struct ${t} has ${nf} fields (1 .. 64, AMFI_MSG_MAX_FIELDS)")
  endif()

  set(c_body "${c_body}/* ${t}.lcm */
static const amfi_msg_field fields_${t}[] = {
${rows}};
static int64_t hash_${t}(void) { return __${ctype}_get_hash(); }
static int decode_${t}(const void *buf, int len, void *msg)
{
    return ${ctype}_decode(buf, 0, len, (${ctype} *)msg);
}
static void cleanup_${t}(void *msg) { ${ctype}_decode_cleanup((${ctype} *)msg); }
int amfi_msg_decode_${t}(const void *buf, size_t len, ${ctype} *msg, char *why,
        size_t whylen)
{
    return amfi_msg_decode_checked(AMFI_MSG_${T_UP}, buf, len, msg, why, whylen);
}

")
  set(desc_lines "${desc_lines}    [AMFI_MSG_${T_UP}] = {\"${t}\", fields_${t}, ${nf}, hash_${t}, sizeof(${ctype}),\n                         decode_${t}, cleanup_${t}},\n")
endforeach()

set(h "/* amfi_msg_types.h: GENERATED by messages/gen_msg_check.cmake from
 * messages/ *.lcm; do not edit. The bus message types for the raw-buffer
 * checker (amfi_msg_check.h) and one typed checked decoder per type. */
#ifndef AMFI_MSG_TYPES_H
#define AMFI_MSG_TYPES_H
#include <stddef.h>
#include \"amfi_messages.h\"

typedef enum {
${enum_lines}    AMFI_MSG_NTYPES
} amfi_msg_type;

/* X(ENUM, type) for every type, e.g. X(AMFI_MSG_VEHICLE_T, vehicle_t): code
 * per type (amfi_##type##_decode_cleanup ...) without a list to keep. */
#define AMFI_MSG_FOR_EACH(X)${each_lines}

/* amfi_msg_decode_checked() for one type: 0 (AMFI_MSG_OK) and *msg decoded
 * (free with TYPE_decode_cleanup), or an amfi_msg_reason > 0 with *msg
 * zeroed and nothing allocated. */
${decl_lines}
#endif /* AMFI_MSG_TYPES_H */
")
set(c "/* amfi_msg_fields.c: GENERATED by messages/gen_msg_check.cmake from
 * messages/ *.lcm; do not edit. The wire layout of every bus message type
 * for the checker in messages/amfi_msg_check.c. */
#include \"amfi_msg_check_impl.h\"

${c_body}const amfi_msg_desc amfi_msg_descs[AMFI_MSG_NTYPES] = {
${desc_lines}};
")
file(WRITE ${OUT_DIR}/amfi_msg_types.h "${h}")
file(WRITE ${OUT_DIR}/amfi_msg_fields.c "${c}")
