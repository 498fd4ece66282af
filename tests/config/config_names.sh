#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# config_names.sh: every global symbol the config library defines carries its
# prefix: amfi_config_ (the public API, amfi_config.h, amfi_config_keys.h,
# amfi_as_built.h) or amfi_cfg_ (the loader's internal helpers and tables,
# shared between config/'s files). A short name such as `fail` or `show`
# would clash with any program linking the library.
#
# usage: config_names.sh PATH/TO/libamfi_config.a
set -u

lib=${1:?usage: config_names.sh LIBAMFI_CONFIG_A}
NM=${NM:-nm}
[ -r "$lib" ] || { echo "config_names.sh: $lib: cannot read" >&2; exit 1; }

syms=$("$NM" -g --defined-only "$lib" 2>&1) ||
    { echo "config_names.sh: $NM $lib failed: $syms" >&2; exit 1; }
# "member.o:" headers and blank lines aside, each line is "VALUE TYPE NAME"
all=$(printf '%s\n' "$syms" | awk 'NF == 3 { print $3 }' | sort -u)
n=$(printf '%s\n' "$all" | grep -c .)
[ "$n" -gt 0 ] || { echo "config_names.sh: no defined symbols in $lib" >&2; exit 1; }
bad=$(printf '%s\n' "$all" | grep -Ev '^amfi_(cfg|config)_')
if [ -n "$bad" ]; then
    echo "config_names.sh: $lib defines symbols without the amfi_config_ or amfi_cfg_ prefix" \
         "(prefix them, or make them static):" >&2
    printf '  %s\n' $bad >&2
    exit 1
fi
echo "config_names.sh: $n global symbols, all prefixed"
