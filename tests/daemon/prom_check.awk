# SPDX-License-Identifier: GPL-3.0-or-later
# prom_check.awk: check a Prometheus text-format file (exposition format 0.0.4)
# as node-exporter's textfile collector reads it: every line is "# HELP name
# text", "# TYPE name type" or a sample "name{label="value",...} value"; every
# sample's metric has its TYPE line before it (a histogram's or summary's
# _bucket/_sum/_count samples belong to their base name); the file ends with
# amfid's last metric (amfi_metrics_write_errors_total), so a cut file fails.
# Prints "prom_check: N samples" or the first problem; exit 0 / 1.
BEGIN { bad = ""; n = 0; last = "" }
function problem(msg) { if (bad == "") bad = FILENAME ":" FNR ": " msg }
/^# HELP [a-zA-Z_:][a-zA-Z0-9_:]* / { help[$3] = 1; next }
/^# TYPE [a-zA-Z_:][a-zA-Z0-9_:]* (counter|gauge|histogram|summary|untyped)$/ {
  if (!($3 in help)) problem("TYPE of " $3 " without HELP")
  type[$3] = $4; next
}
/^#/ { problem("a comment that is neither HELP nor TYPE: " $0); next }
{
  line = $0
  if (line !~ /^[a-zA-Z_:][a-zA-Z0-9_:]*(\{[a-zA-Z_][a-zA-Z0-9_]*="([^"\\]|\\.)*"(,[a-zA-Z_][a-zA-Z0-9_]*="([^"\\]|\\.)*")*\})? (NaN|[+-]Inf|[-+]?[0-9]+(\.[0-9]+)?([eE][-+]?[0-9]+)?)$/) {
    problem("not a sample line: " line); next
  }
  name = line; sub(/[{ ].*/, "", name)
  base = name
  if (!(base in type)) { sub(/_(bucket|sum|count)$/, "", base) }
  if (!(base in type)) problem("sample of " name " before its TYPE")
  else if (base != name && type[base] != "histogram" && type[base] != "summary")
    problem(name " is not a sample of a histogram or summary")
  n++; last = name
}
END {
  if (bad == "" && n == 0) bad = FILENAME ": no samples"
  if (bad == "" && last != "amfi_metrics_write_errors_total") bad = FILENAME ": cut short (last sample " last ")"
  if (bad != "") { print "prom_check: " bad; exit 1 }
  print "prom_check: " n " samples"
}
