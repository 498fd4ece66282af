#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Install the Debian packages amfi needs to build and test; a no-op when they
# are all present. Run as root on Debian 12 (bookworm).
set -euo pipefail
pkgs=(
  cmake make gcc pkg-config      # build
  libopenblas-dev liblapacke-dev # dense linear algebra (BLAS, LAPACK, LAPACKE)
  libyaml-dev                    # configuration files
  zlib1g-dev                     # gzip-compressed passage CSVs
  libgsl-dev                     # random numbers and statistics
  libcmocka-dev                  # unit tests
  gnuplot-nox                    # plots of the experiments (amfi-paper)
  liblcm-dev                     # LCM C library: the amfi bus (messages/)
  libglib2.0-dev                 # lcm.pc requires glib-2.0; liblcm-dev does not pull it in
  libsodium-dev                  # HMAC-SHA-512-256 of the signed bus (messages/amfi_auth.c)
  libmseed-dev                   # MiniSEED 2 records (libmseed 2.19): amfi-ingest reads data loggers (tools/ingest/)
  libmicrohttpd-dev              # HTTP server of amfi-web (tools/web/): the read-only dashboard and JSON API
  libjs-chart.js                 # Chart.js, served locally by amfi-web (no CDN: sites have no internet)
  chromium                       # headless browser: the web_* tests load amfi-web's pages and check what they draw
  liblcm-bin                     # lcm-gen, lcm-logger, lcm-logplayer
  liblcm-java                    # lcm.jar: lcm-spy (tools/ops/amfi-spy)
  default-jdk-headless           # javac, jar: amfi_types.jar for lcm-spy
  default-jre                    # AWT/X11 runtime that lcm-spy's window needs
  libjchart2d-java               # lcm-spy's chart library
  xvfb                           # headless X server for the amfi_spy test
  x11-apps                       # xwd: the amfi_spy test's screenshot
  iproute2                       # ip: the amfi_spy test's private network namespace
  nftables                       # nft: the contrib_nft test checks contrib/amfi-bus.nft
  libsystemd-dev                 # sd_notify, watchdog, journal (amfid)
  libsqlite3-dev                 # the store of passages, indicators, alerts (store/)
  sqlite3                        # sqlite3 CLI: queries on the store, report_cli test fixture
  scdoc                          # man pages (man/*.scd -> roff)
  man-db                         # man -l: the install test renders every page
  systemd                        # systemd-analyze verify; pkg-config systemd (unit directories)
  dpkg-dev                       # dpkg-shlibdeps (the .deb's runtime dependencies), dpkg-buildflags (scripts/package.sh)
  file                           # cpack's DEB generator needs it for dpkg-shlibdeps
  devscripts                     # hardening-check: the deb test checks the packaged programs' hardening
  libjansson-dev                 # JSON output of the tools (common/amfi_json.c): escaped strings
  clang                          # libFuzzer builds of fuzz/ (the fuzz_* tests, docs/fuzzing.md)
  libclang-rt-14-dev             # clang 14's libFuzzer and sanitizer runtimes (-fsanitize=fuzzer)
  libpq-dev                      # libpq: amfi-sync ships site stores to the central PostgreSQL (fleet/)
  postgresql                     # initdb, pg_ctl: the fleet_* tests start a throwaway server
  openssl                        # openssl req: fleet_security's self-signed server certificate (TLS)
  prometheus                     # promtool: the contrib_monitoring test checks and unit-tests
                                 #   contrib/prometheus/amfi-alerts.yml (the server itself is not used)
  python3-yaml                   # the contrib_monitoring test reads the alert rules' YAML
  python3-numpy                  # tools/research/multi-r5: the offline analysis behind
                                 #   docs/results/multi-vehicle.md round five (nothing built needs it)
)
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "install-deps: installing ${missing[*]}"
  if [ "$(id -u)" -ne 0 ]; then
    echo "install-deps: missing packages and not root; run: apt-get install -y ${missing[*]}" >&2
    exit 1
  fi
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
