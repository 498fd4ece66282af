/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_config.c: unit tests of the YAML site loader (config/amfi_config.h).
 *
 * The shipped paper-20m.yaml (but for the paper's solver.modes and
 * max_axles) and sim_publisher.yaml must load to exactly
 * amfi_config_defaults(), the other shipped files must load; a file changing
 * every key must land every value in its field; and each bad
 * input of the table below must fail with one line naming ":LINE: key.path"
 * and the problem, leaving the caller's struct untouched. Files are written
 * with mkstemp under /tmp and removed afterwards.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <math.h>
#include <string.h>
#include <unistd.h>

#include "amfi_config.h"

#ifndef AMFI_CONFIG_DIR
#error "AMFI_CONFIG_DIR (the config/ source folder) must be defined"
#endif

#define ERRLEN 512

/* Write `text` (len bytes) to a fresh temporary file; its name into path. */
static void write_temp(const char *text, size_t len, char path[64])
{
    int fd;

    snprintf(path, 64, "/tmp/amfi_test_config_XXXXXX");
    fd = mkstemp(path);
    assert_true(fd >= 0);
    assert_int_equal((ssize_t)len, write(fd, text, len));
    assert_int_equal(0, close(fd));
}

/* Load `text` as a site file into *c; err gets the message. */
static int load_text(const char *text, amfi_site_config *c, char *err)
{
    char path[64];
    int rc;

    write_temp(text, strlen(text), path);
    rc = amfi_config_load(path, c, err, ERRLEN);
    unlink(path);
    return rc;
}

/* ---- good files ---------------------------------------------------------- */

static void test_defaults(void **state)
{
    amfi_site_config c;
    amfi_bridge_params b;
    amfi_solver_params s;
    amfi_lambda l;

    (void)state;
    amfi_config_defaults(&c);
    amfi_bridge_params_paper20(&b);
    amfi_solver_params_default(&s, 20.0);
    s.free_initial_state = 1; /* the site recommendation over the library's minimum */
    s.pre_roll_s = 0.3;
    s.modes = AMFI_MODES_RESOLVED; /* a site's solver (config/amfid.yaml) */
    s.n_modes = 0;
    s.max_axles = 6;
    amfi_lambda_default(&l);
    assert_string_equal("paper-20m", c.name);
    assert_memory_equal(&b, &c.bridge, sizeof b);
    assert_memory_equal(&s, &c.solver, sizeof s);
    assert_memory_equal(&l, &c.lambda, sizeof l);
    assert_int_equal(0, c.sensor_id[0]);
    for (int i = 1; i < AMFI_MAX_SENSORS; i++)
        assert_int_equal(-1, c.sensor_id[i]);

    /* simulation: sim_publisher's built-in values before the section existed */
    assert_string_equal("", c.sim.population);
    assert_int_equal(10, c.sim.vehicles);
    assert_int_equal(0, c.sim.first);
    assert_true(c.sim.seed == 1);
    assert_true(c.sim.damage == 0.0);
    assert_int_equal(-1, c.sim.damage_step_at);
    assert_int_equal('A', c.sim.profile_class);
    assert_int_equal(0, c.sim.environment);
    assert_true(c.sim.time_compression == 1.0);
    assert_true(c.sim.track_std == 2.0 && c.sim.scan_rate_hz == 1000.0);
    assert_true(c.sim.noise == 0.0);
    assert_true(c.sim.speed_err_mean == 0.0 && c.sim.speed_err_std == 0.0);
    assert_int_equal(0, c.sim.preceding);
    assert_true(c.sim.pre_s == 0.5 && c.sim.post_s == 0.5 && c.sim.dt_s == 1e-4);
    assert_string_equal("", c.sim.lcm_url);
    assert_string_equal("", c.sim.log);
    assert_true(c.sim.speedup == 1.0 && c.sim.headway_s == 0.0);
    assert_true(c.sim.flow_veh_h == 0.0 && c.sim.min_headway_s == 0.5 && c.sim.lanes == 1);
    assert_true(c.sim.noise_ms2 == 0.0);
    assert_int_equal(100, c.sim.block);
    assert_true(c.sim.start_utime == 1767225600000000LL);
    assert_true(c.sim.detector_lead_s == 1.0);
}

/* site: the id and name as given; the name follows bridge.name when left
 * out; coordinates both or none. */
static void test_site_section(void **state)
{
    amfi_site_config c;
    char err[ERRLEN];

    (void)state;
    amfi_config_defaults(&c);
    assert_string_equal("local", c.site.id);
    assert_string_equal("paper-20m", c.site.name);
    assert_true(isnan(c.site.latitude) && isnan(c.site.longitude));
    assert_int_equal(0, load_text("bridge:\n  name: sava-42\nsite:\n  id: si.sava-42_N\n",
                                  &c, err));
    assert_string_equal("si.sava-42_N", c.site.id);
    assert_string_equal("sava-42", c.site.name);
    assert_int_equal(0, load_text("site:\n  id: x\n  name: \"Most čez Savo, km 42\"\n"
                                  "  latitude: 46.05\n  longitude: -14.5\n", &c, err));
    assert_string_equal("Most čez Savo, km 42", c.site.name);
    assert_true(c.site.latitude == 46.05 && c.site.longitude == -14.5);
    assert_string_equal("", c.site.bridge_type);
    assert_int_equal(0, load_text("site:\n  bridge_type: prestressed concrete slab\n", &c, err));
    assert_string_equal("prestressed concrete slab", c.site.bridge_type);
    assert_true(amfi_config_site_id_valid("a-b.c_9"));
    assert_false(amfi_config_site_id_valid(""));
    assert_false(amfi_config_site_id_valid("a b"));
    assert_false(amfi_config_site_id_valid(NULL));
}

static void test_shipped_file_is_the_defaults(void **state)
{
    amfi_site_config want, got;
    char err[ERRLEN];
    int rc;

    (void)state;
    amfi_config_defaults(&want);
    memset(&got, 0xa5, sizeof got); /* every byte must be written */
    rc = amfi_config_load(AMFI_CONFIG_DIR "/paper-20m.yaml", &got, err, sizeof err);
    if (rc)
        fail_msg("%s", err);
    /* the paper's own solver choices, against a site's defaults (resolved
     * modes, six axles: config/amfid.yaml) */
    assert_int_equal(AMFI_MODES_OBSERVABLE, got.solver.modes);
    assert_int_equal(2, got.solver.max_axles);
    assert_int_equal(AMFI_MODES_RESOLVED, want.solver.modes);
    assert_int_equal(6, want.solver.max_axles);
    want.solver.modes = AMFI_MODES_OBSERVABLE;
    want.solver.max_axles = 2;
    assert_string_equal(want.name, got.name);
    assert_true(got.bridge.span_m == 20.0 && got.bridge.n_elements == 20);
    assert_true(got.bridge.E_pa == 3.5e10 && got.bridge.A_m2 == 2.046);
    assert_true(got.bridge.I_m4 == 0.2991 && got.bridge.density_kgm3 == 2400.0);
    assert_true(got.lambda.lambda_ref == 7.94e-9 && !got.lambda.automatic);
    assert_true(got.solver.sensor_x_m[0] == 10.0 && got.solver.n_sensors == 1);
    assert_memory_equal(&want.bridge, &got.bridge, sizeof want.bridge);
    assert_memory_equal(&want.solver, &got.solver, sizeof want.solver);
    assert_memory_equal(&want.lambda, &got.lambda, sizeof want.lambda);
    assert_memory_equal(&want, &got, sizeof want);
}

/* sim_publisher's shipped file: the same bridge and sensors, the channels
 * and the simulation section all at their defaults. */
static void test_shipped_sim_file_is_the_defaults(void **state)
{
    amfi_site_config want, got;
    char err[ERRLEN];
    int rc;

    (void)state;
    amfi_config_defaults(&want);
    memset(&got, 0xa5, sizeof got);
    rc = amfi_config_load(AMFI_CONFIG_DIR "/sim_publisher.yaml", &got, err, sizeof err);
    if (rc)
        fail_msg("%s", err);
    assert_memory_equal(&want.sim, &got.sim, sizeof want.sim);
    assert_memory_equal(&want.bridge, &got.bridge, sizeof want.bridge);
    assert_memory_equal(&want, &got, sizeof want);
}

/* The daemon's files load (their simulation: sections, if any, accepted). */
static void test_other_shipped_files_load(void **state)
{
    static const char *const files[] = {AMFI_CONFIG_DIR "/amfid.yaml",
                                        AMFI_CONFIG_DIR "/demo.yaml"};
    amfi_site_config c;
    char err[ERRLEN];

    (void)state;
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++)
        if (amfi_config_load(files[i], &c, err, sizeof err))
            fail_msg("%s", err);
}

static const char every_key[] =
    "# every key changed from its default\n"
    "bridge:\n"
    "  name: 'A9 Kühbach'\n"
    "  span_m: 30.5\n"
    "  elements: 61\n"
    "  E_pa: 3.0e10\n"
    "  A_m2: 3.5\n"
    "  I_m4: 0.75\n"
    "  density_kgm3: 2500\n"
    "  damping: {ratio: 0.02, modes: [1, 3]}\n"
    "  supports:\n"
    "    - {at_m: 0, type: fixed}\n"
    "    - {at_m: 15.25, type: roller}\n"
    "    - at_m: 30.5\n"
    "      type: pinned\n"
    "  damage: 0.1\n"
    "sensors:\n"
    "  - {id: 7, at_m: 15.25}\n"
    "  - {id: 3, at_m: 7.5, weight: 0.5}\n"
    "  - {id: 255, at_m: 30.5, weight: 2}\n"
    "solver:\n"
    "  formulation: \"paper\"\n"
    "  coordinates: nodal\n"
    "  modes: 6\n"
    "  calc_rate_hz: 2000\n"
    "  initial_force: zero\n"
    "  initial_state: rest\n"
    "  pre_roll_s: 0.2\n"
    "  post_roll_s: 0.5\n"
    "  max_axles: 5\n"
    "  max_duration_s: 4.5\n"
    "  lambda: auto\n"
    "  lambda_ref_rate_hz: 1000\n"
    "  lcurve: {lo: 1e-12, hi: 1e-6, per_decade: 4, refine: 0}\n";

static void test_every_key(void **state)
{
    amfi_site_config c;
    char err[ERRLEN];

    (void)state;
    if (load_text(every_key, &c, err))
        fail_msg("%s", err);
    assert_string_equal("A9 Kühbach", c.name);
    assert_true(c.bridge.span_m == 30.5);
    assert_int_equal(61, c.bridge.n_elements);
    assert_true(c.bridge.E_pa == 3.0e10 && c.bridge.A_m2 == 3.5);
    assert_true(c.bridge.I_m4 == 0.75 && c.bridge.density_kgm3 == 2500.0);
    assert_true(c.bridge.damping_ratio == 0.02);
    assert_int_equal(1, c.bridge.rayleigh_mode_a);
    assert_int_equal(3, c.bridge.rayleigh_mode_b);
    assert_int_equal(3, c.bridge.n_supports);
    assert_true(c.bridge.supports[0].x_m == 0.0);
    assert_int_equal(1, c.bridge.supports[0].restrain_w);
    assert_int_equal(1, c.bridge.supports[0].restrain_theta);
    assert_true(c.bridge.supports[1].x_m == 15.25);
    assert_int_equal(1, c.bridge.supports[1].restrain_w);
    assert_int_equal(0, c.bridge.supports[1].restrain_theta);
    assert_true(c.bridge.supports[2].x_m == 30.5);
    assert_int_equal(0, c.bridge.supports[2].restrain_theta);
    assert_true(c.bridge.damage == 0.1);

    assert_int_equal(3, c.solver.n_sensors);
    assert_int_equal(7, c.sensor_id[0]);
    assert_int_equal(3, c.sensor_id[1]);
    assert_int_equal(255, c.sensor_id[2]);
    assert_int_equal(-1, c.sensor_id[3]);
    assert_true(c.solver.sensor_x_m[0] == 15.25 && c.solver.sensor_weight[0] == 1.0);
    assert_true(c.solver.sensor_x_m[1] == 7.5 && c.solver.sensor_weight[1] == 0.5);
    assert_true(c.solver.sensor_x_m[2] == 30.5 && c.solver.sensor_weight[2] == 2.0);

    assert_int_equal(AMFI_FORM_PAPER, c.solver.formulation);
    assert_int_equal(AMFI_COORDS_NODAL, c.solver.coords);
    assert_int_equal(AMFI_MODES_COUNT, c.solver.modes);
    assert_int_equal(6, c.solver.n_modes);
    assert_true(c.solver.calc_rate_hz == 2000.0);
    assert_int_equal(1, c.solver.fix_initial_force);
    assert_true(c.solver.pre_roll_s == 0.2 && c.solver.post_roll_s == 0.5);
    assert_int_equal(5, c.solver.max_axles);
    assert_true(c.solver.max_duration_s == 4.5);

    assert_int_equal(1, c.lambda.automatic);
    assert_true(c.lambda.lambda_ref == 7.94e-9); /* auto keeps the fixed default */
    assert_true(c.lambda.ref_rate_hz == 1000.0);
    assert_true(c.lambda.lcurve_lo == 1e-12 && c.lambda.lcurve_hi == 1e-6);
    assert_int_equal(4, c.lambda.lcurve_per_decade);
    assert_int_equal(0, c.lambda.lcurve_refine_points);
}

/* Every key of simulation: changed from its default. The file is written
 * under /tmp, so the relative population lands there. */
static const char every_sim_key[] =
    "simulation:\n"
    "  population: traffic/wim.csv\n"
    "  vehicles: 500\n"
    "  first: 7\n"
    "  seed: 4294967295\n"
    "  damage: 0.2\n"
    "  damage_step_at: 200\n"
    "  profile: smooth\n"
    "  track_std: 0.5\n"
    "  scan_rate_hz: 2000\n"
    "  noise: 0.05\n"
    "  speed_error: {mean: -0.01, std: 0.02}\n"
    "  preceding_gap: [-1.5, 2]\n"
    "  pre_s: 0.25\n"
    "  post_s: 1.5\n"
    "  dt_s: 5e-5\n"
    "  environment: site\n"
    "  time_compression: 365\n"
    "  stream:\n"
    "    lcm_url: udpm://239.255.76.99:7667?ttl=0\n"
    "    log: out/traffic.lcmlog\n"
    "    speedup: 25\n"
    "    headway_s: 2\n"
    "    flow_veh_h: 1200\n"
    "    min_headway_s: 0.8\n"
    "    lanes: 2\n"
    "    noise_ms2: 0.003\n"
    "    block: 160\n"
    "    start_utime: 4000000000000000\n"
    "    detector_lead_s: 0.5\n";

static void test_every_sim_key(void **state)
{
    amfi_site_config c, d;
    char err[ERRLEN];

    (void)state;
    if (load_text(every_sim_key, &c, err))
        fail_msg("%s", err);
    assert_string_equal("/tmp/traffic/wim.csv", c.sim.population);
    assert_int_equal(500, c.sim.vehicles);
    assert_int_equal(7, c.sim.first);
    assert_true(c.sim.seed == 4294967295LL);
    assert_true(c.sim.damage == 0.2);
    assert_int_equal(200, c.sim.damage_step_at);
    assert_int_equal(0, c.sim.profile_class);
    assert_true(c.sim.track_std == 0.5 && c.sim.scan_rate_hz == 2000.0);
    assert_true(c.sim.noise == 0.05);
    assert_true(c.sim.speed_err_mean == -0.01 && c.sim.speed_err_std == 0.02);
    assert_int_equal(1, c.sim.preceding);
    assert_true(c.sim.gap_lo_s == -1.5 && c.sim.gap_hi_s == 2.0);
    assert_true(c.sim.pre_s == 0.25 && c.sim.post_s == 1.5 && c.sim.dt_s == 5e-5);
    assert_int_equal(1, c.sim.environment);
    assert_true(c.sim.time_compression == 365.0);
    assert_string_equal("udpm://239.255.76.99:7667?ttl=0", c.sim.lcm_url);
    assert_string_equal("out/traffic.lcmlog", c.sim.log); /* not the file's folder */
    assert_true(c.sim.speedup == 25.0 && c.sim.headway_s == 2.0);
    assert_true(c.sim.flow_veh_h == 1200.0 && c.sim.min_headway_s == 0.8);
    assert_int_equal(2, c.sim.lanes);
    assert_true(c.sim.noise_ms2 == 0.003);
    assert_int_equal(160, c.sim.block);
    assert_true(c.sim.start_utime == 4000000000000000LL);
    assert_true(c.sim.detector_lead_s == 0.5);

    /* the rest of the site untouched */
    amfi_config_defaults(&d);
    assert_memory_equal(&d.bridge, &c.bridge, sizeof d.bridge);
    assert_memory_equal(&d.daemon, &c.daemon, sizeof d.daemon);
}

/* The words and nulls of simulation: (max, none, null, a single gap). */
static void test_sim_words(void **state)
{
    amfi_site_config c;
    char err[ERRLEN];

    (void)state;
    if (load_text("simulation:\n  damage_step_at: none\n  preceding_gap: 1.5\n"
                  "  population: /data/wim.csv\n  profile: H\n"
                  "  stream: {speedup: max, headway_s: null, log: ~, lcm_url: none}\n",
                  &c, err))
        fail_msg("%s", err);
    assert_int_equal(-1, c.sim.damage_step_at);
    assert_int_equal(1, c.sim.preceding);
    assert_true(c.sim.gap_lo_s == 1.5 && c.sim.gap_hi_s == 1.5);
    assert_string_equal("/data/wim.csv", c.sim.population); /* absolute: as given */
    assert_int_equal('H', c.sim.profile_class);
    assert_true(c.sim.speedup == 0.0); /* max: no pacing */
    assert_true(c.sim.headway_s == 0.0);
    assert_string_equal("", c.sim.log);
    assert_string_equal("none", c.sim.lcm_url);

    if (load_text("simulation:\n  damage_step_at:\n  preceding_gap: ~\n  population: ''\n"
                  "  stream: {speedup: 0.01, headway_s: 0}\n",
                  &c, err))
        fail_msg("%s", err);
    assert_int_equal(-1, c.sim.damage_step_at);
    assert_int_equal(0, c.sim.preceding);
    assert_true(c.sim.gap_lo_s == 0.0 && c.sim.gap_hi_s == 0.0);
    assert_string_equal("", c.sim.population);
    assert_true(c.sim.speedup == 0.01 && c.sim.headway_s == 0.0);

    if (load_text("simulation: {damage_step_at: 0, preceding_gap: none, "
                  "scan_rate_hz: 20000, dt_s: 1e-6, seed: 0}\n", &c, err))
        fail_msg("%s", err);
    assert_int_equal(0, c.sim.damage_step_at);
    assert_int_equal(0, c.sim.preceding);
    assert_true(c.sim.seed == 0);
}

/* A relative population follows the file's folder; a bare file name, read
 * from the working directory, stays as it is. */
static void test_sim_population_folder(void **state)
{
    static const char text[] = "simulation: {population: wim.csv}\n";
    amfi_site_config c;
    char err[ERRLEN], cwd[4096], *dir;
    FILE *f;

    (void)state;
    assert_non_null(getcwd(cwd, sizeof cwd));
    dir = mkdtemp((char[]){"/tmp/amfi_test_config_XXXXXX"});
    assert_non_null(dir);
    assert_int_equal(0, chdir(dir));
    f = fopen("site.yaml", "w");
    assert_non_null(f);
    assert_int_equal(1, fwrite(text, sizeof text - 1, 1, f));
    assert_int_equal(0, fclose(f));
    if (amfi_config_load("site.yaml", &c, err, sizeof err))
        fail_msg("%s", err);
    assert_string_equal("wim.csv", c.sim.population);
    if (amfi_config_load("./site.yaml", &c, err, sizeof err))
        fail_msg("%s", err);
    assert_string_equal("./wim.csv", c.sim.population);
    assert_int_equal(0, unlink("site.yaml"));
    assert_int_equal(0, chdir(cwd));
    assert_int_equal(0, rmdir(dir));
}

/* Without supports and sensors, they follow span_m; everything else stays. */
static void test_span_follows(void **state)
{
    amfi_site_config c, d;
    char err[ERRLEN];

    (void)state;
    if (load_text("bridge: {span_m: 30}\nsolver: {modes: all, lambda: 1e-10}\n", &c, err))
        fail_msg("%s", err);
    amfi_config_defaults(&d);
    assert_true(c.bridge.span_m == 30.0);
    assert_int_equal(2, c.bridge.n_supports);
    assert_true(c.bridge.supports[0].x_m == 0.0 && c.bridge.supports[1].x_m == 30.0);
    assert_int_equal(1, c.solver.n_sensors);
    assert_true(c.solver.sensor_x_m[0] == 15.0);
    assert_int_equal(0, c.sensor_id[0]);
    assert_int_equal(AMFI_MODES_ALL, c.solver.modes);
    assert_int_equal(0, c.lambda.automatic);
    assert_true(c.lambda.lambda_ref == 1e-10);
    assert_int_equal(d.bridge.n_elements, c.bridge.n_elements);
    assert_true(c.solver.calc_rate_hz == d.solver.calc_rate_hz);
}

/* The daemon's indicator settings are the engine's own parameters, with the
 * engine's defaults. */
static void test_indicator_defaults_are_the_engines(void **state)
{
    amfi_site_config c;
    amfi_indicator_params p;
    char err[ERRLEN];

    (void)state;
    memset(&p, 0, sizeof p);
    amfi_indicator_params_default(&p);
    amfi_config_defaults(&c);
    assert_memory_equal(&p, &c.daemon.indicators, sizeof p);
    assert_int_equal(0, amfi_indicator_params_check(&c.daemon.indicators, NULL, NULL, 0));
    if (load_text("daemon:\n  indicators: {window: 20, mean_shift: off, "
                  "std_clear_ratio: 1.08}\n", &c, err))
        fail_msg("%s", err);
    assert_int_equal(20, c.daemon.indicators.window);
    assert_int_equal(0, c.daemon.indicators.mean_shift);
    assert_true(c.daemon.indicators.std_clear_ratio == 1.08); /* = alert: allowed */
    /* amfid's filter in front of the engine, and the event limits (issue 13) */
    assert_int_equal(0, c.daemon.single_presence_only);
    assert_int_equal(1, c.daemon.ind_temp_compensated); /* issue 14: compensated */
    assert_true(c.daemon.max_event_s == 10.0);
    assert_int_equal(AMFI_MAX_EVENT_AXLES, c.daemon.max_event_axles);
    if (load_text("daemon:\n  max_event_s: 0\n  max_event_axles: 6\n"
                  "  indicators: {single_presence_only: on, temperature: raw}\n", &c, err))
        fail_msg("%s", err);
    assert_int_equal(1, c.daemon.single_presence_only);
    assert_int_equal(0, c.daemon.ind_temp_compensated);
    assert_true(c.daemon.max_event_s == 0.0);
    assert_int_equal(6, c.daemon.max_event_axles);
}

/* Steps and workspace just under the bounds load; just over, they do not. */
static void test_workspace_bounds(void **state)
{
    amfi_site_config c;
    char err[ERRLEN];

    (void)state;
    /* 1 300 001 steps × 8 B × (2·1 + 2·2 + 2·(2·20 + 2)) = 0.87 GiB (two
     * axles, the observable modes: the paper's choices) */
    if (load_text("solver: {calc_rate_hz: 1e6, max_duration_s: 1, max_axles: 2,"
                  " modes: observable}\n", &c, err))
        fail_msg("%s", err);
    assert_true(c.solver.calc_rate_hz == 1e6);
    assert_int_equal(-1, load_text("solver: {calc_rate_hz: 1e6, max_duration_s: 1.3,"
                                   " max_axles: 2, modes: observable}\n", &c, err));
    assert_non_null(strstr(err, ":1: solver.calc_rate_hz: the solver's workspace would be"));
    /* 10 000 000 steps (56 B each with one axle and one mode): at the bound */
    if (load_text("solver: {calc_rate_hz: 1e6, max_duration_s: 9.699999, max_axles: 1,"
                  " modes: 1}\n", &c, err))
        fail_msg("%s", err);
    assert_int_equal(-1, load_text("solver: {calc_rate_hz: 1e6, max_duration_s: 9.7,"
                                   " max_axles: 1, modes: 1}\n", &c, err));
    assert_non_null(strstr(err, ":1: solver.calc_rate_hz: 1e+06 Hz over (max_duration_s "
                                "9.7 + pre_roll_s 0.3 + post_roll_s 0) s is 10000001 "
                                "solver steps, above the limit of 10000000 steps"));
}

/* A short list replaces the default list whole; unused slots are cleared. */
static void test_list_replaces(void **state)
{
    amfi_site_config c;
    char err[ERRLEN];

    (void)state;
    if (load_text("bridge:\n  supports: [{at_m: 0, type: fixed}]\n"
                  "sensors: [{id: 4, at_m: 20}]\n",
                  &c, err))
        fail_msg("%s", err);
    assert_int_equal(1, c.bridge.n_supports);
    assert_true(c.bridge.supports[1].x_m == 0.0 && c.bridge.supports[1].restrain_w == 0);
    assert_int_equal(1, c.solver.n_sensors);
    assert_int_equal(4, c.sensor_id[0]);
    assert_true(c.solver.sensor_x_m[0] == 20.0);
}

/* ---- bad inputs ---------------------------------------------------------- */

typedef struct bad_case {
    const char *name;
    const char *yaml;
    int line;            /* expected line, 0: the message has none */
    const char *path;    /* expected key path right after "FILE:LINE: " */
    const char *problem; /* a fragment of the problem */
} bad_case;

static const bad_case bad_cases[] = {
    {"unknown_key", "solver:\n  calc_rate_hz: 5000\n  lamda: 1e-9\n", 3, "solver.lamda",
     "unknown key"},
    {"unknown_section", "bridge: {}\nmonitor:\n  bus: udpm://\n", 2, "monitor",
     "unknown key (known: site, bridge, sensors, solver, daemon, simulation, alerts, metrics, report, detector, ingest, classes)"},
    {"classes_scheme", "classes:\n  scheme: tls8\n", 2, "classes.scheme", "eu, fhwa13"},
    {"classes_group_spacing", "classes:\n  group_spacing_m: 3\n", 2, "classes.group_spacing_m",
     "[1, 2.5]"},
    {"classes_gvw_small", "classes:\n  scheme: eu\n  gvw_limit_kg:\n    A23: 500\n", 4,
     "classes.gvw_limit_kg.A23", "0 (none) or 1000 .. 100000 kg"},
    {"classes_unknown_class", "classes:\n  gvw_limit_kg:\n    A24: 40000\n", 3,
     "classes.gvw_limit_kg.A24", "unknown key (known: CAR, R2, R3, R4, A22, A23, A32, A33)"},
    {"classes_container", "classes:\n  container_44t: yes\n", 2, "classes.container_44t",
     "off, on"},
    {"report_gvw_zero", "report:\n  limits:\n    gvw_kg: 0\n", 3, "report.limits.gvw_kg",
     "(0, 1e+06]"},
    {"report_axle_text", "report:\n  limits:\n    axle_kg: heavy\n", 3,
     "report.limits.axle_kg", "expected a finite number"},
    {"report_bin", "report:\n  histogram_bin_kg: 50\n", 2, "report.histogram_bin_kg",
     "[100, 100000]"},
    {"alerts_timeout_zero", "alerts:\n  command_timeout_s: 0\n", 2, "alerts.command_timeout_s",
     "(0, 3600]"},
    {"alerts_max_running", "alerts:\n  command_max_running: 65\n", 2,
     "alerts.command_max_running", "1 .. 64"},
    {"alerts_command_relative", "alerts:\n  command: notify.sh\n", 2, "alerts.command",
     "must be an absolute path"},
    {"alerts_command_missing", "alerts:\n  command: /nonexistent/notify\n", 2,
     "alerts.command", "is not a file"},
    {"alerts_command_not_exec", "alerts:\n  command: /etc/passwd\n", 2, "alerts.command",
     "is not executable"},
    {"metrics_relative", "metrics:\n  textfile: amfid.prom\n", 2, "metrics.textfile",
     "must be an absolute path"},
    {"metrics_no_folder", "metrics:\n  textfile: /nonexistent/amfid.prom\n", 2,
     "metrics.textfile", "the folder '/nonexistent' does not exist"},
    {"metrics_interval", "metrics:\n  interval_s: 0.5\n", 2, "metrics.interval_s", "[1, 3600]"},
    {"site_id_empty", "site:\n  id: ''\n", 2, "site.id", "must be 1 .. 63 bytes of A-Z"},
    {"site_id_space", "site:\n  id: my bridge\n", 2, "site.id",
     "must be 1 .. 63 bytes of A-Z a-z 0-9 _ . -, got 'my bridge'"},
    {"site_id_slash", "site:\n  id: a/b\n", 2, "site.id", "got 'a/b'"},
    {"site_id_long", "site:\n  id: "
     "aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa\n", 2, "site.id",
     "1 .. 63 bytes"},
    {"site_id_list", "site:\n  id: [a]\n", 2, "site.id", "expected a site id"},
    {"site_name_control", "site:\n  name: \"a\\tb\"\n", 2, "site.name",
     "must not contain control characters"},
    {"site_lat_range", "site:\n  latitude: 91\n  longitude: 0\n", 2, "site.latitude",
     "[-90, 90]"},
    {"site_lon_text", "site:\n  latitude: 1\n  longitude: east\n", 3, "site.longitude",
     "expected a finite number, got 'east'"},
    {"site_lat_alone", "\nsite:\n  latitude: 46\n", 3, "site.latitude",
     "give both site.latitude and site.longitude"},
    {"site_bridge_type_control", "site:\n  bridge_type: \"slab\\tgirder\"\n", 2,
     "site.bridge_type", "must not contain control characters"},
    {"site_bridge_type_long", "site:\n  bridge_type: "
     "aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa\n", 2, "site.bridge_type",
     "must be 1 .. 63 bytes long"},
    {"site_unknown", "site:\n  idd: x\n", 2, "site.idd",
     "unknown key (known: id, name, latitude, longitude, bridge_type)"},
    {"sim_not_map", "simulation: 10\n", 1, "simulation", "expected a mapping"},
    {"sim_unknown_key", "simulation:\n  vehicles: 5\n  vehicle: 5\n", 3,
     "simulation.vehicle", "unknown key (known: population, vehicles, first"},
    {"sim_stream_unknown_key", "simulation:\n  stream:\n    url: udpm://\n", 3,
     "simulation.stream.url", "unknown key (known: lcm_url, log, speedup"},
    {"sim_duplicate", "simulation:\n  seed: 1\n  seed: 2\n", 3, "simulation.seed",
     "duplicate key (first at line 2)"},
    {"sim_vehicles_zero", "simulation:\n  vehicles: 0\n", 2, "simulation.vehicles",
     "must be 1 .. 10000000, got 0"},
    {"sim_vehicles_fraction", "simulation:\n  vehicles: 2.5\n", 2, "simulation.vehicles",
     "expected an integer"},
    {"sim_first_negative", "simulation:\n  first: -1\n", 2, "simulation.first",
     "0 .. 10000000"},
    {"sim_seed_big", "simulation:\n  seed: 4294967296\n", 2, "simulation.seed",
     "must be 0 .. 4294967295, got '4294967296'"},
    {"sim_seed_huge", "simulation:\n  seed: 99999999999999999999999\n", 2,
     "simulation.seed", "must be 0 .. 4294967295"},
    {"sim_seed_word", "simulation:\n  seed: random\n", 2, "simulation.seed",
     "expected an integer, got 'random'"},
    {"sim_damage", "simulation:\n  damage: 0.95\n", 2, "simulation.damage",
     "must be in [0, 0.9], got 0.95"},
    {"sim_step_word", "simulation:\n  damage_step_at: later\n", 2,
     "simulation.damage_step_at", "expected none or a vehicle index, got 'later'"},
    {"sim_step_negative", "simulation:\n  damage_step_at: -1\n", 2,
     "simulation.damage_step_at", "must be none or 0 .. 10000000, got -1"},
    {"sim_step_list", "simulation:\n  damage_step_at: [1]\n", 2,
     "simulation.damage_step_at", "got a list"},
    {"sim_profile", "simulation:\n  profile: Z\n", 2, "simulation.profile",
     "expected one of A, B, C, D, E, F, G, H, smooth; got 'Z'"},
    {"sim_profile_lower", "simulation:\n  profile: a\n", 2, "simulation.profile",
     "got 'a'"},
    {"sim_environment", "simulation:\n  environment: winter\n", 2, "simulation.environment",
     "expected one of none, site; got 'winter'"},
    {"sim_time_compression", "simulation:\n  time_compression: 0.5\n", 2,
     "simulation.time_compression", "[1, 1e+06]"},
    {"sim_track_std", "simulation:\n  track_std: 101\n", 2, "simulation.track_std",
     "[0, 100]"},
    {"sim_scan_rate", "simulation:\n  scan_rate_hz: 30\n", 2, "simulation.scan_rate_hz",
     "[50, 20000]"},
    {"sim_noise", "simulation:\n  noise: -0.1\n", 2, "simulation.noise", "[0, 1]"},
    {"sim_speed_error_scalar", "simulation:\n  speed_error: 0.01\n", 2,
     "simulation.speed_error", "expected a mapping"},
    {"sim_speed_error_std", "simulation:\n  speed_error:\n    mean: 0\n    std: -0.1\n",
     4, "simulation.speed_error.std", "must be in [0, 0.5], got -0.1"},
    {"sim_speed_error_mean", "simulation:\n  speed_error: {mean: 0.6}\n", 2,
     "simulation.speed_error.mean", "[-0.5, 0.5]"},
    {"sim_speed_error_unknown", "simulation:\n  speed_error: {sd: 0.1}\n", 2,
     "simulation.speed_error.sd", "unknown key (known: mean, std)"},
    {"sim_gap_lo_above_hi", "simulation:\n  preceding_gap: [3, 1]\n", 2,
     "simulation.preceding_gap", "lo (3) must not exceed hi (1)"},
    {"sim_gap_three", "simulation:\n  preceding_gap: [1, 2, 3]\n", 2,
     "simulation.preceding_gap", "expected [lo, hi] (two numbers), got 3"},
    {"sim_gap_item_range", "simulation:\n  preceding_gap:\n    - -3\n    - 1\n", 3,
     "simulation.preceding_gap[0]", "must be in [-2, 30], got -3"},
    {"sim_gap_single_range", "simulation:\n  preceding_gap: 31\n", 2,
     "simulation.preceding_gap", "[-2, 30]"},
    {"sim_gap_word", "simulation:\n  preceding_gap: some\n", 2, "simulation.preceding_gap",
     "'some'"},
    {"sim_gap_map", "simulation:\n  preceding_gap: {lo: 1}\n", 2,
     "simulation.preceding_gap", "expected null, a number or [lo, hi], got a mapping"},
    {"sim_pre", "simulation:\n  pre_s: 31\n", 2, "simulation.pre_s", "[0, 30]"},
    {"sim_post", "simulation:\n  post_s: -1\n", 2, "simulation.post_s", "[0, 30]"},
    {"sim_dt", "simulation:\n  dt_s: 1e-2\n", 2, "simulation.dt_s", "[1e-06, 0.001]"},
    {"sim_dt_not_sub_sample", "simulation:\n  scan_rate_hz: 3000\n", 2,
     "simulation.scan_rate_hz", "1/(scan_rate_hz*dt_s) = 3.33333 steps per sample is not"},
    {"sim_dt_not_sub_sample_dt", "simulation:\n  scan_rate_hz: 1000\n  dt_s: 3e-4\n", 3,
     "simulation.dt_s", "not an integer"},
    {"sim_population_control", "simulation:\n  population: \"a\\nb.csv\"\n", 2,
     "simulation.population", "control characters"},
    {"sim_population_list", "simulation:\n  population: [a.csv]\n", 2,
     "simulation.population", "expected a file path, got a list"},
    {"sim_speedup_zero", "simulation:\n  stream:\n    speedup: 0\n", 3,
     "simulation.stream.speedup", "must be max or in [0.01, 1e+06], got 0"},
    {"sim_speedup_word", "simulation:\n  stream: {speedup: fast}\n", 2,
     "simulation.stream.speedup", "expected max or a number, got 'fast'"},
    {"sim_speedup_quoted", "simulation:\n  stream: {speedup: \"25\"}\n", 2,
     "simulation.stream.speedup", "got '25'"},
    {"sim_speedup_null", "simulation:\n  stream: {speedup: ~}\n", 2,
     "simulation.stream.speedup", "no value"},
    {"sim_headway", "simulation:\n  stream: {headway_s: 0.05}\n", 2,
     "simulation.stream.headway_s",
     "must be 0 or null (the population's timestamps) or in [0.1, 3600], got 0.05"},
    {"sim_flow", "simulation:\n  stream: {flow_veh_h: 0.5}\n", 2,
     "simulation.stream.flow_veh_h", "must be 0 or null (off) or in [1, 3600], got 0.5"},
    {"sim_min_headway", "simulation:\n  stream: {min_headway_s: -1}\n", 2,
     "simulation.stream.min_headway_s", "[0, 60]"},
    {"sim_lanes", "simulation:\n  stream: {lanes: 3}\n", 2, "simulation.stream.lanes",
     "1 .. 2"},
    {"sim_headway_word", "simulation:\n  stream: {headway_s: population}\n", 2,
     "simulation.stream.headway_s", "'population'"},
    {"sim_noise_ms2", "simulation:\n  stream: {noise_ms2: 11}\n", 2,
     "simulation.stream.noise_ms2", "[0, 10]"},
    {"sim_block", "simulation:\n  stream: {block: 161}\n", 2, "simulation.stream.block",
     "1 .. 160"},
    {"sim_start_utime_zero", "simulation:\n  stream: {start_utime: 0}\n", 2,
     "simulation.stream.start_utime", "must be 1 .. 4000000000000000, got '0'"},
    {"sim_start_utime_float", "simulation:\n  stream: {start_utime: 1.7e15}\n", 2,
     "simulation.stream.start_utime", "expected an integer"},
    {"sim_detector_lead", "simulation:\n  stream: {detector_lead_s: 61}\n", 2,
     "simulation.stream.detector_lead_s", "[0, 60]"},
    {"sim_lcm_url_long",
     "simulation:\n  stream:\n    lcm_url: udpm://"
     "aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa"
     "aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa"
     "aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa\n",
     3, "simulation.stream.lcm_url", "must be 0 .. 255 characters long, got 264"},
    {"sim_log_quoted_control", "simulation:\n  stream: {log: \"a\\tb\"}\n", 2,
     "simulation.stream.log", "control characters"},
    {"unknown_daemon_key", "daemon:\n  bux: udpm://\n", 2, "daemon.bux",
     "unknown key (known: lcm_url, channels"},
    {"daemon_workers_zero", "daemon:\n  workers: 0\n", 2, "daemon.workers", "1 .. 64"},
    {"daemon_channel_empty", "daemon:\n  channels: {accel: \"\"}\n", 2,
     "daemon.channels.accel", "characters long"},
    /* issue 13: events of vehicles weighed together */
    {"daemon_event_axles_one", "daemon:\n  max_event_axles: 1\n", 2, "daemon.max_event_axles",
     "2 .. 48"},
    {"daemon_event_negative", "daemon:\n  max_event_s: -1\n", 2, "daemon.max_event_s",
     "[0, 600]"},
    {"daemon_event_beyond_ring", "daemon:\n  ring_s: 20\n  max_event_s: 30\n", 3,
     "daemon.max_event_s", "30 s is not below daemon.ring_s (20 s)"},
    /* issue 14, item 4: the natural frequency */
    {"daemon_free_beyond_ring",
     "daemon:\n  ring_s: 10\n  max_event_s: 9\n  natural_frequency: {free_s: 2}\n", 4,
     "daemon.natural_frequency.free_s", "2 s after an event of up to daemon.max_event_s (9 s)"},
    {"daemon_band_inverted", "daemon:\n  natural_frequency:\n    f_lo_hz: 8\n    f_hi_hz: 4\n",
     4, "daemon.natural_frequency.f_hi_hz", "f_hi_hz must be above f_lo_hz"},
    {"daemon_free_negative", "daemon:\n  natural_frequency: {free_s: -1}\n", 2,
     "daemon.natural_frequency.free_s", "[0, 30]"},
    {"daemon_modes_four", "daemon:\n  natural_frequency: {modes: 4}\n", 2,
     "daemon.natural_frequency.modes", "1 .. 3"},
    {"daemon_natfreq_mode", "daemon:\n  natural_frequency:\n    mode: 21\n", 3,
     "daemon.natural_frequency.mode", "0 .. 20"},
    {"daemon_natfreq_band", "daemon:\n  natural_frequency:\n    band: 0\n", 3,
     "daemon.natural_frequency.band", "(0, 0.5]"},
    {"daemon_natfreq_mode_model", "daemon:\n  natural_frequency:\n    mode: 12\n", 3,
     "daemon.natural_frequency.mode", "is not inside [f_lo_hz, f_hi_hz] = [0.5, 50] Hz"},
    {"daemon_single_presence_bad", "daemon:\n  indicators: {single_presence_only: yes}\n", 2,
     "daemon.indicators.single_presence_only", "off"},
    {"daemon_temperature_bad", "daemon:\n  indicators: {temperature: on}\n", 2,
     "daemon.indicators.temperature", "compensated"},
    {"daemon_classes_unknown", "daemon:\n  indicators:\n    classes: A23,B7\n", 3,
     "daemon.indicators.classes", "'B7' is not a class of classes.scheme eu"},
    {"daemon_classes_fhwa_in_eu", "daemon:\n  indicators: {classes: FHWA9}\n", 2,
     "daemon.indicators.classes", "'FHWA9' is not a class"},
    {"daemon_classes_twice", "daemon:\n  indicators: {classes: \"A23,A33,A23\"}\n", 2,
     "daemon.indicators.classes", "'A23' twice"},
    {"daemon_classes_empty_name", "daemon:\n  indicators: {classes: \"A23,\"}\n", 2,
     "daemon.indicators.classes", "an empty name"},
    {"daemon_min_gvw_negative", "daemon:\n  indicators: {min_gvw_kg: -1}\n", 2,
     "daemon.indicators.min_gvw_kg", "[0, 100000]"},
    {"daemon_clear_above_alert",
     "daemon:\n  indicators: {std_alert_ratio: 1.05, std_clear_ratio: 1.2}\n", 2,
     "daemon.indicators.std_clear_ratio", "must not exceed"},
    {"daemon_alert_below_default_clear",
     "daemon:\n  indicators:\n    mean_alert_ratio: 1.02\n", 3,
     "daemon.indicators.mean_clear_ratio", "must not exceed mean_alert_ratio = 1.02"},
    /* issue 9 item 6: refused at load, with the line and the limit, not later
     * "out of memory for 600300001 steps" */
    {"steps_over_limit", "solver:\n  calc_rate_hz: 1e6\n  max_duration_s: 600\n", 2,
     "solver.calc_rate_hz", "is 600300001 solver steps, above the limit of 10000000 steps"},
    {"steps_over_limit_rolls", "solver:\n  max_duration_s: 600\n  post_roll_s: 59\n"
     "  pre_roll_s: 59\n  calc_rate_hz: 14000\n", 5, "solver.calc_rate_hz",
     "is 10052001 solver steps, above the limit of 10000000"},
    {"workspace_over_limit", "solver:\n  max_duration_s: 600\n  max_axles: 12\n", 2,
     "solver.max_duration_s", "14.54 GiB (3001501 steps of 12 axles over 40 states), "
     "above the limit of 1 GiB per solver"},
    {"workspace_over_limit_nodal", "bridge:\n  elements: 400\nsolver:\n"
     "  coordinates: nodal\n  initial_state: rest\n  max_axles: 4\n", 6,
     "solver.max_axles", "steps of 4 axles over 3200 states), above the limit of 1 GiB"},
    /* a refusal of libamfi's bridge model names the file and the line */
    {"model_refused", "bridge:\n  density_kgm3: 1e-200\n  A_m2: 1e-200\n", 1, "bridge",
     "the bridge model is refused: eigenproblem failed"},
    {"unknown_key_in_item", "sensors:\n  - {id: 0, at_m: 1}\n  - {id: 1, pos: 2}\n", 3,
     "sensors[1].pos", "unknown key"},
    {"map_for_scalar", "bridge:\n  span_m: {value: 20}\n", 2, "bridge.span_m",
     "expected a number, got a mapping"},
    {"list_for_scalar", "bridge:\n  E_pa: [1, 2]\n", 2, "bridge.E_pa",
     "expected a number, got a list"},
    {"not_a_number", "bridge:\n  A_m2: abc\n", 2, "bridge.A_m2", "'abc'"},
    {"trailing_garbage", "bridge:\n  name: x\n  span_m: 20m\n", 3, "bridge.span_m",
     "'20m'"},
    {"nan", "bridge:\n  I_m4: .nan\n", 2, "bridge.I_m4", "finite number"},
    {"inf", "bridge:\n  density_kgm3: inf\n", 2, "bridge.density_kgm3", "finite number"},
    {"overflow", "bridge:\n  E_pa: 1e999\n", 2, "bridge.E_pa", "out of range"},
    {"hex", "bridge:\n  span_m: 0x14\n", 2, "bridge.span_m", "'0x14'"},
    {"quoted_number", "bridge:\n  span_m: \"20\"\n", 2, "bridge.span_m", "quoted string"},
    {"null_value", "bridge:\n  span_m:\n  elements: 4\n", 2, "bridge.span_m", "no value"},
    {"duplicate_key", "bridge:\n  span_m: 20\n  elements: 10\n  span_m: 30\n", 4,
     "bridge.span_m", "duplicate key (first at line 2)"},
    {"duplicate_section", "solver: {}\nbridge: {}\nsolver: {modes: all}\n", 3, "solver",
     "duplicate key (first at line 1)"},
    {"section_not_map", "bridge: 5\n", 1, "bridge", "expected a mapping"},
    {"key_not_name", "bridge:\n  ? [a, b]\n  : 1\n", 2, "bridge", "key must be"},
    {"nul_in_key", "bridge:\n  \"span_m\\0x\": 20\n", 2, "bridge.span_m?x",
     "unknown key"},
    {"span_zero", "bridge:\n  span_m: 0\n", 2, "bridge.span_m", "must be > 0, got 0"},
    {"elements_zero", "bridge:\n  elements: 0\n", 2, "bridge.elements", "1 .. 1000"},
    {"elements_big", "bridge:\n  elements: 1001\n", 2, "bridge.elements", "got 1001"},
    {"elements_fraction", "bridge:\n  elements: 2.5\n", 2, "bridge.elements",
     "expected an integer"},
    {"E_negative", "bridge:\n  E_pa: -3.5e10\n", 2, "bridge.E_pa", "must be > 0"},
    {"damping_ratio_one", "bridge:\n  damping:\n    ratio: 1\n", 3,
     "bridge.damping.ratio", "[0, 1)"},
    {"damping_unknown", "bridge:\n  damping: {ratio: 0.03, mode: [1, 2]}\n", 2,
     "bridge.damping.mode", "unknown key"},
    {"damping_same_modes", "bridge:\n  damping: {modes: [2, 2]}\n", 2,
     "bridge.damping.modes", "must differ"},
    {"damping_one_mode", "bridge:\n  damping: {modes: [1]}\n", 2, "bridge.damping.modes",
     "two mode numbers"},
    {"damping_mode_zero", "bridge:\n  damping:\n    modes:\n      - 1\n      - 0\n", 5,
     "bridge.damping.modes[1]", "mode number"},
    {"damping_mode_past_dofs", "bridge:\n  elements: 1\n  damping: {modes: [1, 9]}\n", 3,
     "bridge.damping.modes", "only 2 modes"},
    {"supports_empty", "bridge:\n  supports: []\n", 2, "bridge.supports",
     "1 .. 16 supports, got 0"},
    {"supports_17",
     "bridge:\n  supports: [{at_m: 0, type: fixed}, {at_m: 1, type: roller},"
     " {at_m: 2, type: roller}, {at_m: 3, type: roller}, {at_m: 4, type: roller},"
     " {at_m: 5, type: roller}, {at_m: 6, type: roller}, {at_m: 7, type: roller},"
     " {at_m: 8, type: roller}, {at_m: 9, type: roller}, {at_m: 10, type: roller},"
     " {at_m: 11, type: roller}, {at_m: 12, type: roller}, {at_m: 13, type: roller},"
     " {at_m: 14, type: roller}, {at_m: 15, type: roller}, {at_m: 16, type: roller}]\n",
     2, "bridge.supports", "got 17"},
    {"support_type", "bridge:\n  supports:\n    - {at_m: 0, type: pinned}\n"
     "    - {at_m: 20, type: hinge}\n", 4, "bridge.supports[1].type",
     "expected one of pinned, roller, fixed, elastic; got 'hinge'"},
    {"support_no_type", "bridge:\n  supports:\n    - {at_m: 0, type: pinned}\n"
     "    - at_m: 20\n", 4, "bridge.supports[1].type", "missing"},
    {"support_off_span", "bridge:\n  supports:\n    - {at_m: 0, type: pinned}\n"
     "    - {at_m: 25, type: roller}\n", 4, "bridge.supports[1].at_m", "beyond the span"},
    {"support_same_node", "bridge:\n  supports:\n    - {at_m: 0, type: pinned}\n"
     "    - {at_m: 0.3, type: roller}\n", 4, "bridge.supports[1].at_m", "node 0"},
    {"support_mechanism", "bridge:\n  supports:\n    - {at_m: 10, type: pinned}\n", 2,
     "bridge.supports", "free to rotate"},
    {"elastic_no_spring", "bridge:\n  supports:\n    - {at_m: 0, type: pinned}\n"
     "    - {at_m: 20, type: elastic}\n", 4, "bridge.supports[1]", "needs k_w_npm > 0"},
    {"pinned_k_w", "bridge:\n  supports:\n    - {at_m: 0, type: pinned, k_w_npm: 1e9}\n"
     "    - {at_m: 20, type: roller}\n", 3, "bridge.supports[0]", "elastic support"},
    {"fixed_k_theta", "bridge:\n  supports:\n    - {at_m: 0, type: fixed, k_theta_nmprad: 1e9}\n",
     3, "bridge.supports[0]", "holds the rotation"},
    {"k_theta_negative", "bridge:\n  supports:\n    - {at_m: 0, type: pinned, k_theta_nmprad: -1}\n"
     "    - {at_m: 20, type: roller}\n", 3, "bridge.supports[0].k_theta_nmprad", ">= 0"},
    {"elastic_alone", "bridge:\n  supports:\n    - {at_m: 0, type: elastic, k_w_npm: 1e9}\n", 2,
     "bridge.supports", "free to rotate"},
    {"segment_backwards", "bridge:\n  segments:\n    - {from_m: 5, to_m: 2, EI_nm2: 1e10}\n", 3,
     "bridge.segments[0]", "must be beyond from_m"},
    {"segment_empty", "bridge:\n  segments:\n    - {from_m: 0, to_m: 2}\n", 3,
     "bridge.segments[0]", "neither EI_nm2 nor mass_kgpm"},
    {"segment_off_span", "bridge:\n  segments:\n    - {from_m: 15, to_m: 25, mass_kgpm: 6000}\n",
     3, "bridge.segments[0]", "beyond the span"},
    {"segment_overlap", "bridge:\n  segments:\n    - {from_m: 0, to_m: 5, EI_nm2: 2e10}\n"
     "    - {from_m: 4, to_m: 8, EI_nm2: 2e10}\n", 4, "bridge.segments[1]", "overlaps bridge.segments[0]"},
    {"segment_no_to", "bridge:\n  segments:\n    - {from_m: 0, EI_nm2: 2e10}\n", 3,
     "bridge.segments[0].to_m", "missing"},
    {"damage_one", "bridge:\n  damage: 1\n", 2, "bridge.damage", "[0, 1)"},
    {"name_empty", "bridge:\n  name: ''\n", 2, "bridge.name", "1 .. 63 bytes"},
    {"name_long",
     "bridge:\n  name: aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa\n", 2,
     "bridge.name", "got 64"},
    {"name_control", "bridge:\n  name: \"a\\tb\"\n", 2, "bridge.name", "control"},
    {"sensors_not_list", "sensors: {id: 0, at_m: 10}\n", 1, "sensors",
     "expected a list of sensors, got a mapping"},
    {"sensors_9",
     "sensors:\n  - {id: 0, at_m: 1}\n  - {id: 1, at_m: 2}\n  - {id: 2, at_m: 3}\n"
     "  - {id: 3, at_m: 4}\n  - {id: 4, at_m: 5}\n  - {id: 5, at_m: 6}\n"
     "  - {id: 6, at_m: 7}\n  - {id: 7, at_m: 8}\n  - {id: 8, at_m: 9}\n", 2, "sensors",
     "1 .. 8 sensors, got 9"},
    {"sensor_item_scalar", "sensors:\n  - 10\n", 2, "sensors[0]", "expected a mapping"},
    {"sensor_duplicate_id", "sensors:\n  - {id: 3, at_m: 5}\n  - {id: 4, at_m: 6}\n"
     "  - {id: 3, at_m: 7}\n", 4, "sensors[2].id", "duplicate id 3 (also sensors[0])"},
    {"sensor_id_256", "sensors:\n  - {id: 256, at_m: 5}\n", 2, "sensors[0].id",
     "0 .. 255"},
    {"sensor_no_position", "sensors:\n  - id: 0\n    weight: 1\n", 2, "sensors[0].at_m",
     "missing"},
    {"sensor_off_span", "bridge:\n  span_m: 20\nsensors:\n  - {id: 0, at_m: 20.5}\n", 4,
     "sensors[0].at_m", "beyond the span"},
    {"sensor_negative", "sensors:\n  - {id: 0, at_m: -1}\n", 2, "sensors[0].at_m",
     "must be >= 0"},
    {"sensor_weight_zero", "sensors:\n  - {id: 0, at_m: 10, weight: 0}\n", 2,
     "sensors[0].weight", "must be > 0"},
    {"formulation", "solver:\n  formulation: exact\n", 2, "solver.formulation",
     "expected one of paper; got 'exact'"},
    {"coordinates", "solver:\n  coordinates: Modal\n", 2, "solver.coordinates",
     "modal, nodal"},
    {"modes_zero", "solver:\n  modes: 0\n", 2, "solver.modes", "got 0"},
    {"modes_word", "solver:\n  modes: some\n", 2, "solver.modes", "'some'"},
    {"modes_fraction", "solver:\n  modes: 2.5\n", 2, "solver.modes", "'2.5'"},
    {"modes_past_dofs", "solver:\n  modes: 41\n", 2, "solver.modes",
     "the model has only 40"},
    {"calc_rate_zero", "solver:\n  calc_rate_hz: 0\n", 2, "solver.calc_rate_hz",
     "(0, 1e+06]"},
    {"calc_rate_big", "solver:\n  calc_rate_hz: 2e6\n", 2, "solver.calc_rate_hz",
     "got 2e+06"},
    {"initial_force_word", "solver:\n  initial_force: none\n", 2, "solver.initial_force",
     "free, zero"},
    {"initial_zero_no_roll",
     "solver:\n  initial_force: zero\n  initial_state: rest\n  pre_roll_s: 0\n", 2,
     "solver.initial_force", "pre_roll_s > 0"},
    {"initial_state_word", "solver:\n  initial_state: moving\n", 2, "solver.initial_state",
     "rest, free"},
    {"free_state_zero_force", "solver:\n  initial_force: zero\n", 2, "solver.initial_state",
     "initial_force: free"},
    {"free_state_nodal", "solver:\n  coordinates: nodal\n", 2, "solver.initial_state",
     "coordinates: modal"},
    {"pre_roll_60", "solver:\n  pre_roll_s: 60\n", 2, "solver.pre_roll_s", "[0, 60)"},
    {"post_roll_negative", "solver:\n  post_roll_s: -0.1\n", 2, "solver.post_roll_s",
     "got -0.1"},
    {"max_axles", "solver:\n  max_axles: 13\n", 2, "solver.max_axles", "1 .. 12"},
    {"speed_coarse_rate_low", "solver:\n  speed_coarse_rate_hz: 50\n", 2,
     "solver.speed_coarse_rate_hz", "0 (no coarse model) or >= 100"},
    {"speed_coarse_rate_negative", "solver:\n  speed_coarse_rate_hz: -1\n", 2,
     "solver.speed_coarse_rate_hz", "[0, 1e+06]"},
    {"max_duration_zero", "solver:\n  max_duration_s: 0\n", 2, "solver.max_duration_s",
     "(0, 600]"},
    {"lambda_negative", "solver:\n  lambda: -1e-9\n", 2, "solver.lambda",
     "must be > 0 (or auto)"},
    {"lambda_word", "solver:\n  lambda: automatic\n", 2, "solver.lambda",
     "expected auto or a positive number, got 'automatic'"},
    {"lambda_null", "solver:\n  lambda: ~\n", 2, "solver.lambda", "no value"},
    {"lambda_rate_zero", "solver:\n  lambda_ref_rate_hz: 0\n", 2,
     "solver.lambda_ref_rate_hz", "(0, 1e+06]"},
    {"lcurve_lo_above_hi", "solver:\n  lcurve:\n    lo: 1e-3\n    hi: 1e-4\n", 4,
     "solver.lcurve", "must be below hi"},
    {"lcurve_lo_above_default_hi", "solver:\n  lcurve: {lo: 1e-3}\n", 2,
     "solver.lcurve", "lo (0.001) must be below hi"},
    {"lcurve_lo_zero", "solver:\n  lcurve: {lo: 0}\n", 2, "solver.lcurve.lo",
     "must be > 0"},
    {"lcurve_per_decade", "solver:\n  lcurve: {per_decade: 0}\n", 2,
     "solver.lcurve.per_decade", "1 .. 100"},
    {"lcurve_refine", "solver:\n  lcurve: {refine: 101}\n", 2, "solver.lcurve.refine",
     "0 .. 100"},
    {"self_alias", "bridge: &b\n  damping: *b\n", 2, "bridge.damping.damping",
     "unknown key"},
    {"top_list", "- bridge\n- solver\n", 1, NULL, "expected a mapping"},
    {"top_scalar", "hello\n", 1, NULL, "expected a mapping"},
    {"syntax_indent", "bridge:\n  span_m: 20\n   elements: 10\n", 3, NULL,
     "YAML syntax error"},
    {"syntax_flow", "bridge:\n  name: x\nsolver: {modes: all\n\n", 5, NULL,
     "YAML syntax error"},
    {"syntax_tab", "bridge:\n\tspan_m: 20\n", 2, NULL, "YAML syntax error"},
    {"undefined_alias", "bridge:\n  span_m: *x\n", 2, NULL, "undefined alias"},
    {"bad_utf8", "bridge:\n  name: \xff\xfe\n", 2, NULL, "UTF-8"},
    {"two_documents", "bridge: {}\n---\nsolver: {}\n", 2, NULL, "second YAML document"},
    {"too_deep", "bridge:\n  damping:\n    modes: [[[[[[[[[[[[[[[[[[1]]]]]]]]]]]]]]]]]]\n", 3, NULL,
     "nested deeper than 16 levels"},
    /* bounded intake (daemon.intake.*, sensors[].rate_hz) */
    {"sensor_rate_zero", "sensors:\n  - {id: 0, at_m: 5, rate_hz: 0}\n", 2, "sensors[0].rate_hz",
     "(0, 100000]"},
    {"sensor_rates_differ", "sensors:\n  - {id: 0, at_m: 5, rate_hz: 500}\n"
     "  - {id: 1, at_m: 10}\n", 3, "sensors[1].rate_hz",
     "1000 Hz differs from sensors[0].rate_hz (500 Hz): every sensor must send at one rate"},
    {"intake_min_speed", "daemon:\n  intake:\n    min_speed_mps: 60\n", 3,
     "daemon.intake.min_speed_mps", "[1, 60)"},
    {"intake_unknown", "daemon:\n  intake:\n    max_speed_mps: 60\n", 3,
     "daemon.intake.max_speed_mps", "unknown key"},
    {"intake_deck_rate_zero", "daemon:\n  intake:\n    deck_max_rate_c_per_min: 0\n", 3,
     "daemon.intake.deck_max_rate_c_per_min", "(0, 1e+06]"},
    {"intake_calibration_range", "daemon:\n  intake:\n    calibration_min_kg: 20000\n"
     "    calibration_max_kg: 10000\n", 4, "daemon.intake.calibration_max_kg",
     "10000 kg is below calibration_min_kg (20000 kg)"},
    {"intake_sources_space", "daemon:\n  intake:\n    calibration_sources: \"wim 1\"\n", 3,
     "daemon.intake.calibration_sources", "' ' in 'wim 1'"},
    {"intake_sources_empty_name", "daemon:\n  intake:\n    calibration_sources: \"a,,b\"\n", 3,
     "daemon.intake.calibration_sources", "an empty name in 'a,,b'"},
    {"empty", "", 1, NULL, "empty file"},
    {"comments_only", "# nothing\n\n", 1, NULL, "empty file"},
};

static void test_bad(void **state)
{
    const bad_case *bc = *state;
    amfi_site_config c, before;
    char err[ERRLEN], want[256], path[64];
    int rc;

    memset(&c, 0x5a, sizeof c);
    memcpy(&before, &c, sizeof c);
    write_temp(bc->yaml, strlen(bc->yaml), path);
    rc = amfi_config_load(path, &c, err, sizeof err);
    unlink(path);
    print_message("    %s\n", err);
    assert_int_equal(-1, rc);
    assert_memory_equal(&before, &c, sizeof c); /* untouched on failure */
    assert_null(strchr(err, '\n'));
    assert_true(strncmp(err, path, strlen(path)) == 0);
    if (bc->path)
        snprintf(want, sizeof want, "%s:%d: %s: ", path, bc->line, bc->path);
    else
        snprintf(want, sizeof want, "%s:%d: ", path, bc->line);
    if (strncmp(err, want, strlen(want)) != 0)
        fail_msg("want prefix '%s', got '%s'", want, err);
    if (!strstr(err, bc->problem))
        fail_msg("want '%s' in '%s'", bc->problem, err);
}

/* classes: lands in amfi_class_params; absent, the European defaults. */
static void classes_section(void **state)
{
    amfi_site_config c, d;
    char err[ERRLEN];

    (void)state;
    amfi_config_defaults(&d);
    assert_int_equal(d.classes.scheme, AMFI_CLASS_SCHEME_EU);
    assert_true(d.classes.group_spacing_m == 2.0);
    assert_true(d.classes.gvw_limit_kg[AMFI_EU_A23] == 40000.0);
    if (load_text("classes:\n  scheme: fhwa13\n  group_spacing_m: 2.44\n"
                  "  container_44t: on\n  gvw_limit_kg:\n    R2: 19000\n    CAR: 3500\n"
                  "  driving_axle_kg: 11000\n  motor_tandem_air: off\n",
                  &c, err) != 0)
        fail_msg("%s", err);
    assert_int_equal(c.classes.scheme, AMFI_CLASS_SCHEME_FHWA13);
    assert_true(c.classes.group_spacing_m == 2.44);
    assert_int_equal(c.classes.container_44t, 1);
    assert_true(c.classes.gvw_limit_kg[AMFI_EU_R2] == 19000.0);
    assert_true(c.classes.gvw_limit_kg[AMFI_EU_CAR] == 3500.0);
    assert_true(c.classes.gvw_limit_kg[AMFI_EU_R3] == 26000.0); /* not given: default */
    assert_true(c.classes.driving_axle_kg == 11000.0);
    assert_int_equal(c.classes.motor_tandem_air, 0);
}

/* Bearings with springs and segments land in libamfi's parameters. */
static void bearings_and_segments(void **state)
{
    amfi_site_config c;
    char err[ERRLEN];

    (void)state;
    if (load_text("bridge:\n"
                  "  supports:\n"
                  "    - {at_m: 0, type: pinned, k_theta_nmprad: 5.2e8}\n"
                  "    - {at_m: 20, type: elastic, k_w_npm: 4e9, k_theta_nmprad: 1e8}\n"
                  "  segments:\n"
                  "    - {from_m: 0, to_m: 3, EI_nm2: 1.6e10}\n"
                  "    - {from_m: 3, to_m: 17, mass_kgpm: 5400}\n",
                  &c, err))
        fail_msg("%s", err);
    assert_int_equal(2, c.bridge.n_supports);
    assert_int_equal(1, c.bridge.supports[0].restrain_w);
    assert_int_equal(0, c.bridge.supports[0].restrain_theta);
    assert_true(c.bridge.supports[0].k_w_npm == 0 && c.bridge.supports[0].k_theta_nmprad == 5.2e8);
    assert_int_equal(0, c.bridge.supports[1].restrain_w);
    assert_int_equal(0, c.bridge.supports[1].restrain_theta);
    assert_true(c.bridge.supports[1].k_w_npm == 4e9 && c.bridge.supports[1].k_theta_nmprad == 1e8);
    assert_int_equal(2, c.bridge.n_segments);
    assert_true(c.bridge.segments[0].x0_m == 0 && c.bridge.segments[0].x1_m == 3);
    assert_true(c.bridge.segments[0].EI_nm2 == 1.6e10 && c.bridge.segments[0].mass_kgpm == 0);
    assert_true(c.bridge.segments[1].mass_kgpm == 5400 && c.bridge.segments[1].EI_nm2 == 0);
}

/* ---- files and buffers ---------------------------------------------------- */

static void test_missing_file(void **state)
{
    amfi_site_config c;
    char err[ERRLEN];

    (void)state;
    assert_int_equal(-1, amfi_config_load("/nonexistent/site.yaml", &c, err, sizeof err));
    assert_string_equal("/nonexistent/site.yaml: cannot open: No such file or directory",
                        err);
    assert_int_equal(-1, amfi_config_load("/tmp", &c, err, sizeof err));
    assert_string_equal("/tmp: not a regular file", err);
    assert_int_equal(-1, amfi_config_load(NULL, &c, err, sizeof err));
    assert_non_null(strstr(err, "NULL"));
    assert_int_equal(-1, amfi_config_load("/tmp/x.yaml", NULL, err, sizeof err));
}

static void test_too_large(void **state)
{
    amfi_site_config c;
    char err[ERRLEN], path[64];
    size_t n = (1u << 20) + 1;
    char *big = malloc(n);

    (void)state;
    assert_non_null(big);
    memset(big, '#', n); /* one long comment */
    write_temp(big, n, path);
    free(big);
    assert_int_equal(-1, amfi_config_load(path, &c, err, sizeof err));
    unlink(path);
    assert_non_null(strstr(err, "too large"));
}

/* Deep flow nesting: a clear error at once (libyaml alone would take 30 s
 * for this one: its scanner is quadratic in the nesting depth). */
static void test_deep_nesting(void **state)
{
    amfi_site_config c;
    char err[ERRLEN], path[64];
    size_t depth = 100000, n = 2 * depth + 1;
    char *deep = malloc(n);

    (void)state;
    assert_non_null(deep);
    memset(deep, '[', depth);
    memset(deep + depth, ']', depth);
    deep[n - 1] = '\n';
    write_temp(deep, n, path);
    free(deep);
    assert_int_equal(-1, amfi_config_load(path, &c, err, sizeof err));
    unlink(path);
    assert_non_null(strstr(err, ":1: nested deeper than 16 levels"));
}

/* Small, NULL and zero-length error buffers: truncated, never overrun. */
static void test_error_buffer(void **state)
{
    amfi_site_config c;
    char path[64], small[16];
    const char *text = "solver:\n  lamda: 1\n";

    (void)state;
    write_temp(text, strlen(text), path);
    assert_int_equal(-1, amfi_config_load(path, &c, NULL, 0));
    memset(small, 'x', sizeof small);
    assert_int_equal(-1, amfi_config_load(path, &c, small, 1));
    assert_int_equal('\0', small[0]);
    assert_int_equal('x', small[1]);
    assert_int_equal(-1, amfi_config_load(path, &c, small, sizeof small));
    assert_int_equal(sizeof small - 1, strlen(small));
    assert_true(strncmp(small, path, sizeof small - 1) == 0);
    unlink(path);
}

int main(void)
{
    static const struct CMUnitTest fixed[] = {
        cmocka_unit_test(test_defaults),
        cmocka_unit_test(bearings_and_segments),
        cmocka_unit_test(classes_section),
        cmocka_unit_test(test_site_section),
        cmocka_unit_test(test_shipped_file_is_the_defaults),
        cmocka_unit_test(test_shipped_sim_file_is_the_defaults),
        cmocka_unit_test(test_other_shipped_files_load),
        cmocka_unit_test(test_every_key),
        cmocka_unit_test(test_every_sim_key),
        cmocka_unit_test(test_sim_words),
        cmocka_unit_test(test_sim_population_folder),
        cmocka_unit_test(test_span_follows),
        cmocka_unit_test(test_list_replaces),
        cmocka_unit_test(test_indicator_defaults_are_the_engines),
        cmocka_unit_test(test_workspace_bounds),
        cmocka_unit_test(test_missing_file),
        cmocka_unit_test(test_too_large),
        cmocka_unit_test(test_deep_nesting),
        cmocka_unit_test(test_error_buffer),
    };
    enum {
        N_FIXED = sizeof fixed / sizeof fixed[0],
        N_BAD = sizeof bad_cases / sizeof bad_cases[0]
    };
    struct CMUnitTest tests[N_FIXED + N_BAD];

    memcpy(tests, fixed, sizeof fixed);
    for (size_t i = 0; i < N_BAD; i++)
        tests[N_FIXED + i] = (struct CMUnitTest){
            .name = bad_cases[i].name,
            .test_func = test_bad,
            .initial_state = (void *)&bad_cases[i],
        };
    return cmocka_run_group_tests_name("config", tests, NULL, NULL);
}
