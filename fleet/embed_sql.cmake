# SPDX-License-Identifier: GPL-3.0-or-later
# cmake -DIN=roles.sql -DOUT=fleet_roles_sql.h -DNAME=fleet_roles_sql_text -P embed_sql.cmake:
# the file's bytes as a C array (NUL-terminated), so that amfi-sync applies
# exactly the file that is installed.
file(READ "${IN}" hex HEX)
string(REGEX REPLACE "([0-9a-f][0-9a-f])" "0x\\1," body "${hex}")
string(REGEX REPLACE "(0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,)" "\\1\n" body "${body}")
file(WRITE "${OUT}.tmp" "/* generated from ${IN} by embed_sql.cmake: do not edit */\nstatic const char ${NAME}[] = {\n${body}0x00};\n")
file(RENAME "${OUT}.tmp" "${OUT}")
