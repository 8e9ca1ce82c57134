/*
 * test_config.c - cdspd's configuration (daemon/config.c): the YAML file,
 * --set, the checks of cdspd_config_finish, and that every error names
 * its place (file:line:column), its key and the problem. The effective
 * configuration written by --check-config reads back to the same values.
 */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <stdio.h>
#include <unistd.h>
#include <sys/stat.h>
#include <arpa/inet.h>
#include <netinet/in.h>
#include <cmocka.h>

#include "config.h"

static char dir[256];
static char calib_path[300];

static int setup(void **state)
{
    FILE *f;
    (void)state;
    snprintf(dir, sizeof dir, "%s/test_config", getenv("CDSPD_TMP") ? getenv("CDSPD_TMP") : "/tmp");
    mkdir(dir, 0755);
    snprintf(calib_path, sizeof calib_path, "%s/cam.yaml", dir);
    f = fopen(calib_path, "w");
    if (!f)
        return -1;
    fputs("image_width: 320\nimage_height: 240\ncamera_matrix:\n  rows: 3\n  cols: 3\n"
          "  data: [400, 0, 159.5, 0, 400, 119.5, 0, 0, 1]\ndistortion_model: plumb_bob\n"
          "distortion_coefficients:\n  rows: 1\n  cols: 5\n  data: [0, 0, 0, 0, 0]\n", f);
    fclose(f);
    return 0;
}

static const char *write_file(const char *name, const char *text)
{
    static char path[400];
    FILE *f;
    snprintf(path, sizeof path, "%s/%s", dir, name);
    f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
    return path;
}

/* load `text` as a file; expect failure with all of the fragments */
static void expect_file_error(const char *text, const char *frag1, const char *frag2)
{
    static cdspd_config c;
    char err[2048] = "";
    const char *path = write_file("bad.yaml", text);
    cdspd_config_defaults(&c);
    if (cdspd_config_load_file(&c, path, err, sizeof err) == 0)
        fail_msg("accepted:\n%s", text);
    if (!strstr(err, frag1) || (frag2 && !strstr(err, frag2)))
        fail_msg("message '%s' lacks '%s' / '%s'", err, frag1, frag2 ? frag2 : "");
}

static void test_defaults(void **state)
{
    static cdspd_config c;
    char err[512];
    cdsp_params p, d;
    (void)state;
    cdspd_config_defaults(&c);
    assert_string_equal(c.source, "sim");
    assert_int_equal(c.format, CDSPD_FORMAT_BINARY);
    assert_int_equal(c.sim.frames, 64);
    assert_true(c.status_interval > 0);
    assert_int_equal(c.log_level, CDSPD_LOG_INFO);
    assert_int_equal(c.log_cat[CDSPD_LOGC_SOURCE], -1);
    assert_int_equal(cdspd_config_log_level(&c, CDSPD_LOGC_SOURCE), CDSPD_LOG_INFO);
    /* the solver keys default to the library's defaults */
    cdspd_config_params(&c, &p);
    cdsp_params_default(&d);
    assert_int_equal(p.edge.step, d.edge.step);
    assert_int_equal(p.edge.half_window, d.edge.half_window);
    assert_true(p.edge.min_contrast == d.edge.min_contrast);
    assert_true(p.track_band_px == d.track_band_px);
    assert_int_equal(p.track_min_inliers, d.track_min_inliers);
    /* required keys */
    assert_int_equal(cdspd_config_finish(&c, err, sizeof err), -1);
    assert_non_null(strstr(err, "key 'calib': required"));
    snprintf(c.calib, sizeof c.calib, "%s", calib_path);
    assert_int_equal(cdspd_config_finish(&c, err, sizeof err), -1);
    assert_non_null(strstr(err, "key 'radius': required"));
    c.radius = 5;
    assert_int_equal(cdspd_config_finish(&c, err, sizeof err), -1);
    assert_non_null(strstr(err, "key 'dest': required"));
    assert_int_equal(cdspd_config_set(&c, "dest", "127.0.0.1:9", "t", err, sizeof err), 0);
    if (cdspd_config_finish(&c, err, sizeof err))
        fail_msg("%s", err);
    assert_int_equal(c.cam.width, 320);
}

static void test_file(void **state)
{
    static cdspd_config c;
    char err[1024], text[2048];
    const char *path;
    (void)state;
    snprintf(text, sizeof text,
             "# a config\n"
             "source: file:/data/*.pgm\n"
             "calib: %s\n"
             "radius: 12.5\n"
             "dest: [127.0.0.1:5000, \"[::1]:5001\", localhost]\n"
             "format: json\n"
             "log:\n  level: warn\n  source: debug\n"
             "sim:\n  center: [1, -2, 300]\n  rate: 100\n"
             "solver:\n  roi: [10, 20, 100, 50]\n  polarity: -1\n"
             /* point_fit before the refine_step it needs (libcdsp
              * refuses it alone): the rule waits for the whole file */
             "  point_fit: true\n  refine_step: 3\n"
             "file: {loop: yes, rate: 0}\n"
             "aravis:\n  packet_socket: off\n",
             calib_path);
    path = write_file("good.yaml", text);
    cdspd_config_defaults(&c);
    if (cdspd_config_load_file(&c, path, err, sizeof err))
        fail_msg("%s", err);
    if (cdspd_config_finish(&c, err, sizeof err))
        fail_msg("%s", err);
    assert_string_equal(c.source, "file:/data/*.pgm");
    assert_true(c.radius == 12.5);
    assert_int_equal(c.n_dest, 3);
    assert_int_equal(c.dest[1].addr.ss_family, AF_INET6);
    assert_string_equal(c.dest[2].text, "localhost");
    assert_int_equal(c.format, CDSPD_FORMAT_JSON);
    assert_int_equal(c.point_fit, 1);
    assert_int_equal(c.refine_step, 3);
    assert_int_equal(cdspd_config_log_level(&c, CDSPD_LOGC_SOURCE), CDSPD_LOG_DEBUG);
    assert_int_equal(cdspd_config_log_level(&c, CDSPD_LOGC_NET), CDSPD_LOG_WARN);
    assert_true(c.sim.center[1] == -2 && c.sim.rate == 100);
    assert_int_equal(c.roi[3], 50);
    assert_int_equal(c.polarity, -1);
    assert_int_equal(c.file.loop, 1);
    assert_int_equal(c.aravis.packet_socket, 0);
    assert_string_equal(c.config_file, path);
    /* --set after the file wins, with the same syntax for lists */
    assert_int_equal(cdspd_config_set(&c, "sim.center", "[4, 5, 6]", "--set", err, sizeof err), 0);
    assert_true(c.sim.center[2] == 6);
    assert_int_equal(cdspd_config_set(&c, "sim.center", "7,8,9", "--set", err, sizeof err), 0);
    assert_true(c.sim.center[0] == 7);
    /* polarity: cdsp_tool's words, the library's numbers as aliases */
    {
        static const struct {
            const char *text;
            int ok, value;
        } pol[] = {{"bright", 1, 1}, {"dark", 1, -1}, {"any", 1, 0}, {"1", 1, 1}, {"-1", 1, -1},
                   {"0", 1, 0},      {"2", 0, 0},     {"Bright", 0, 0}, {"", 0, 0}};
        size_t i;
        for (i = 0; i < sizeof pol / sizeof pol[0]; i++) {
            c.polarity = 7;
            assert_int_equal(cdspd_config_set(&c, "solver.polarity", pol[i].text, "--set", err,
                                              sizeof err), pol[i].ok ? 0 : -1);
            if (pol[i].ok)
                assert_int_equal(c.polarity, pol[i].value);
            else
                assert_non_null(strstr(err, "expected any, bright or dark"));
        }
    }
    /* an empty file is all defaults */
    cdspd_config_defaults(&c);
    path = write_file("empty.yaml", "# nothing\n");
    assert_int_equal(cdspd_config_load_file(&c, path, err, sizeof err), 0);
}

static void test_file_errors(void **state)
{
    (void)state;
    expect_file_error("radius: 3\nsim:\n  rat: 4\n", "bad.yaml:3:3:", "unknown key 'sim.rat'");
    expect_file_error("radius: fast\n", "bad.yaml:1:9:", "key 'radius': expected a number");
    expect_file_error("radius: -1\n", "key 'radius'", "[0, 1e+09]");
    expect_file_error("sim:\n  frames: 2.5\n", "key 'sim.frames': expected an integer", NULL);
    expect_file_error("format: xml\n", "key 'format': expected one of binary|json", "got 'xml'");
    expect_file_error("file:\n  loop: maybe\n", "key 'file.loop': expected true or false", NULL);
    expect_file_error("sim:\n  center: [1, 2]\n", "key 'sim.center': expected 3 numbers", NULL);
    expect_file_error("sim:\n  center: [1, 2, x]\n", "key 'sim.center': item 3", NULL);
    expect_file_error("sim: 4\n", "key 'sim' is a section", NULL);
    expect_file_error("radius:\n  a: 1\n", "key 'radius' takes a value", NULL);
    expect_file_error("radius: [1, 2]\n", "key 'radius': expected number, got a list", NULL);
    expect_file_error("log:\n  level: default\n", "key 'log.level'", NULL);
    expect_file_error("log:\n  net: loud\n", "key 'log.net'", NULL);
    expect_file_error("- a\n- b\n", "bad.yaml:1:1: expected a mapping", NULL);
    expect_file_error("radius: 3\n  bad indent: [\n", "bad.yaml:", "YAML error at line 2");
    {
        static cdspd_config c;
        char err[512];
        cdspd_config_defaults(&c);
        assert_int_equal(cdspd_config_load_file(&c, "/nonexistent/cdspd.yaml", err, sizeof err), -1);
        assert_non_null(strstr(err, "/nonexistent/cdspd.yaml"));
    }
}

static void test_finish_errors(void **state)
{
    static const struct {
        const char *key, *value, *frag;
    } cases[] = {
        {"source", "webcam", "key 'source': unknown source 'webcam'"},
        {"source", "file:", "needs a file name"},
        {"source", "v4l2:", "needs a device"},
        {"source", "sim:x", "'sim' takes no argument"},
        {"dest", "127.0.0.1:0", "port '0': expected 1..65535"},
        {"dest", "127.0.0.1:70000", "port '70000'"},
        {"dest", "no-such-host.invalid:9", "cannot resolve 'no-such-host.invalid'"},
        {"dest", "fe80::1:9", "write IPv6 addresses as [ADDR]:PORT"},
        {"calib", "/nonexistent/cam.yaml", "key 'calib': /nonexistent/cam.yaml"},
        {"solver.roi", "[300, 0, 100, 100]", "key 'solver.roi'"},
        {"retry_min", "20", "key 'retry_min'"},
        {"sim.direction", "0,0,0", "key 'sim.direction'"},
        {"sim.bits", "11", "key 'sim.bits'"},
        {"net.multicast_interface", "eth0", "key 'net.multicast_interface'"},
        {"record", "/proc/cdspd-cannot-be-here", "key 'record': cannot create"},
        /* issue 16 / issue 9 defect 3: values the library refuses, refused
         * at load time (they used to pass --check-config) */
        {"solver.min_contrast", "0", "key 'solver.min_contrast': libcdsp refuses '0'"},
        {"solver.min_contrast", "1", "key 'solver.min_contrast': libcdsp refuses '1'"},
        {"sim.blur", "8.5", "key 'sim.blur': expected a number in [0, 8]"},
        {"sim.blur", "10", "key 'sim.blur'"},
        {"solver.point_fit", "true", "key 'solver.point_fit': needs solver.refine_step 3 or more"},
    };
    size_t i;
    (void)state;
    for (i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        static cdspd_config c;
        char err[2048] = "";
        cdspd_config_defaults(&c);
        snprintf(c.calib, sizeof c.calib, "%s", calib_path);
        c.radius = 5;
        assert_int_equal(cdspd_config_set(&c, "dest", "127.0.0.1:9", "t", err, sizeof err), 0);
        if (cdspd_config_set(&c, cases[i].key, cases[i].value, "--set", err, sizeof err) == 0 &&
            cdspd_config_finish(&c, err, sizeof err) == 0)
            fail_msg("%s=%s accepted", cases[i].key, cases[i].value);
        if (!strstr(err, cases[i].frag))
            fail_msg("%s=%s: message '%s' lacks '%s'", cases[i].key, cases[i].value, err,
                     cases[i].frag);
    }
}

/* Issue 16: a hostile or careless config file. Duplicated keys and
 * sections are refused with the line of both (the last used to win
 * silently); nesting and aliases are bounded before libyaml builds the
 * document (a 120 KB file of '[' took 15 s, blocking a SIGHUP reload; a
 * 60 KB one ~4 s).
 * The small versions are in tests/fuzz/corpus/config/regress-*. */
static void test_hostile_files(void **state)
{
    static cdspd_config c;
    char err[2048] = "", *deep;
    size_t i, n = 60000; /* below the 64 KiB file limit */
    const char *path;
    (void)state;
    expect_file_error("radius: 3\nradius: 4\n", "bad.yaml:2:1: key 'radius' given twice",
                      "first at line 1");
    expect_file_error("sim:\n  rate: 3\nsim:\n  frames: 4\n",
                      "bad.yaml:3:1: section 'sim' given twice", "first at line 1");
    expect_file_error("sim:\n  rate: 3\n  rate: 5\n", "bad.yaml:3:3: key 'sim.rate' given twice",
                      "first at line 2");
    expect_file_error("sim.rate: 3\nsim:\n  rate: 5\n", "bad.yaml:3:3: key 'sim.rate' given twice",
                      "first at line 1");
    expect_file_error("dest: [a:1]\ndest: [b:2]\n", "bad.yaml:2:1: key 'dest' given twice", NULL);
    expect_file_error("solver:\n  min_contrast: 1\n", "bad.yaml:2:17: key 'solver.min_contrast'",
                      "libcdsp refuses");
    /* 9 levels (the root mapping and 8 lists): one beyond the bound */
    expect_file_error("a: [[[[[[[[1]]]]]]]]\n",
                      "bad.yaml: YAML nested deeper than 8 levels at line 1, column 11", NULL);
    {
        char text[2048];
        size_t k = 0;
        k += (size_t)snprintf(text + k, sizeof text - k, "x: &a 1\nl: [");
        for (i = 0; i < 65; i++)
            k += (size_t)snprintf(text + k, sizeof text - k, "%s*a", i ? ", " : "");
        snprintf(text + k, sizeof text - k, "]\n");
        expect_file_error(text, "bad.yaml: more than 64 YAML aliases, at line 2", NULL);
    }
    deep = malloc(n + 1);
    assert_non_null(deep);
    memset(deep, '[', n);
    deep[n] = 0;
    expect_file_error(deep, "nested deeper than 8 levels", NULL);
    free(deep);
    /* what a valid file may use: anchors and a few aliases */
    path = write_file("alias.yaml", "sim:\n  center: &c [1, 2, 450]\n  sway: *c\n");
    cdspd_config_defaults(&c);
    assert_int_equal(cdspd_config_load_file(&c, path, err, sizeof err), 0);
    assert_true(c.sim.sway[2] == 450);
}

/* --check-config's dump is a config file giving the same configuration. */
static void test_dump_round_trip(void **state)
{
    static cdspd_config a, b;
    char err[1024], path[400];
    FILE *f;
    (void)state;
    cdspd_config_defaults(&a);
    snprintf(a.calib, sizeof a.calib, "%s", calib_path);
    assert_int_equal(cdspd_config_set(&a, "radius", "0.1", "t", err, sizeof err), 0);
    assert_int_equal(cdspd_config_set(&a, "dest", "[127.0.0.1:9, \"[::1]:10\"]", "t", err, sizeof err), 0);
    assert_int_equal(cdspd_config_set(&a, "sim.sway", "[0.3, -1e-7, 12345.678901234567]", "t", err,
                                      sizeof err), 0);
    assert_int_equal(cdspd_config_set(&a, "log.proc", "debug", "t", err, sizeof err), 0);
    assert_int_equal(cdspd_config_set(&a, "solver.seed", "18446744073709551615", "t", err, sizeof err), 0);
    assert_int_equal(cdspd_config_set(&a, "source", "file:/a \"quoted\" dir/*.png", "t", err, sizeof err), 0);
    snprintf(path, sizeof path, "%s/dump.yaml", dir);
    f = fopen(path, "w");
    assert_non_null(f);
    cdspd_config_dump(&a, f);
    fclose(f);
    cdspd_config_defaults(&b);
    if (cdspd_config_load_file(&b, path, err, sizeof err))
        fail_msg("%s", err);
    assert_string_equal(a.source, b.source);
    assert_true(a.radius == b.radius);
    assert_int_equal(b.n_dest, 2);
    assert_string_equal(b.dest[1].text, "[::1]:10");
    assert_memory_equal(a.sim.sway, b.sim.sway, sizeof a.sim.sway);
    assert_int_equal(b.log_cat[CDSPD_LOGC_PROC], CDSPD_LOG_DEBUG);
    assert_true(b.seed == UINT64_MAX);
    assert_int_equal(a.aravis.packet_socket, b.aravis.packet_socket);
    assert_true(a.status_interval == b.status_interval);
}

/* The address syntax itself is host/addr.c's (tests/tool/test_host_addr.c);
 * here the source key's kinds. */
static void test_source_kinds(void **state)
{
    const char *arg;
    (void)state;
    assert_int_equal(cdspd_source_kind_parse("aravis", &arg), CDSPD_SRC_ARAVIS);
    assert_string_equal(arg, "");
    assert_int_equal(cdspd_source_kind_parse("aravis:Fake-1", &arg), CDSPD_SRC_ARAVIS);
    assert_string_equal(arg, "Fake-1");
    assert_int_equal(cdspd_source_kind_parse("v4l2:/dev/video0", &arg), CDSPD_SRC_V4L2);
    assert_int_equal(cdspd_source_kind_parse("simx", &arg), -1);
}

/* The MAVLink and mount keys (docs/mavlink.md): values, and errors that
 * name the file's line and the key. */
static void test_mavlink_keys(void **state)
{
    static cdspd_config c;
    char err[1024], text[1024];
    const char *path;
    static const struct {
        const char *text, *frag1, *frag2;
    } bad[] = {
        {"mavlink: [\"udpout://127.0.0.1\"]\n", "bad.yaml:1:1: key 'mavlink'", "udpout://HOST:PORT"},
        {"mavlink: [\"udpout://h:70000\"]\n", "key 'mavlink'", "PORT 1..65535"},
        {"mavlink: [\"serial:///dev/ttyS0:12345\"]\n", "baud rate '12345'", NULL},
        {"mavlink: [\"serial://ttyS0:57600\"]\n", "serial:///dev/DEVICE:BAUD", NULL},
        {"mavlink: [\"tcp://1.2.3.4:5760\"]\n", "expected udpout://", NULL},
        {"\nmount: sideways\n", "bad.yaml:2:8: key 'mount': unknown preset 'sideways'", NULL},
        {"mount: [down, 1, 2]\n", "key 'mount': expected PRESET", NULL},
        {"mount: [0, -90, 0, 0, 0, x]\n", "key 'mount': item 6", NULL},
        {"mavlink_component_id: 256\n", "key 'mavlink_component_id'", "[1, 255]"},
        {"mavlink_rate: -1\n", "key 'mavlink_rate'", NULL},
    };
    size_t i;
    (void)state;
    for (i = 0; i < sizeof bad / sizeof bad[0]; i++)
        expect_file_error(bad[i].text, bad[i].frag1, bad[i].frag2);
    snprintf(text, sizeof text,
             "calib: %s\nradius: 3\n"
             "mavlink: [\"udpout://127.0.0.1:14550\", \"serial_flowcontrol:///dev/ttyUSB0:921600\"]\n"
             "mavlink_system_id: 2\nmavlink_component_id: 192\nmavlink_rate: 12.5\n"
             "mavlink_position: false\nmount: [down-aft, 10, -20, 30]\n",
             calib_path);
    path = write_file("mav.yaml", text);
    cdspd_config_defaults(&c);
    assert_true(c.mavlink_system_id == 1 && c.mavlink_component_id == 191 && c.mavlink_position_valid);
    if (cdspd_config_load_file(&c, path, err, sizeof err) || cdspd_config_finish(&c, err, sizeof err))
        fail_msg("%s", err); /* no dest: a MAVLink link is enough */
    assert_int_equal(c.n_dest, 0);
    assert_int_equal(c.n_mavlink, 2);
    assert_string_equal(c.mavlink[1], "serial_flowcontrol:///dev/ttyUSB0:921600");
    assert_int_equal(c.mavlink_system_id, 2);
    assert_int_equal(c.mavlink_component_id, 192);
    assert_true(c.mavlink_rate == 12.5 && !c.mavlink_position_valid);
    assert_true(c.mount[0] == 0 && c.mount[1] == -90 && c.mount[2] == 180);
    assert_true(c.mount[3] == 10 && c.mount[4] == -20 && c.mount[5] == 30);
    assert_int_equal(cdspd_config_set(&c, "mount", "[1, 2, 3, 4, 5, 6]", "t", err, sizeof err), 0);
    assert_true(c.mount[0] == 1 && c.mount[5] == 6);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_defaults),       cmocka_unit_test(test_file),
        cmocka_unit_test(test_file_errors),    cmocka_unit_test(test_finish_errors),
        cmocka_unit_test(test_dump_round_trip), cmocka_unit_test(test_source_kinds),
        cmocka_unit_test(test_hostile_files),
        cmocka_unit_test(test_mavlink_keys),
    };
    return cmocka_run_group_tests_name("daemon-config", tests, setup, NULL);
}
