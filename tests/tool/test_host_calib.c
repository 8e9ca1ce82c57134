/*
 * test_host_calib.c - the ROS camera_info YAML: a file as ROS's
 * camera_calibration writes it, the writer's round trip, and a table of
 * malformed or incomplete files, each refused with the file name, the
 * field's path and the problem.
 */
#define _POSIX_C_SOURCE 200809L
#include "tool_test.h"

#include <math.h>

#include "cdsp_host.h"

/* As written by ROS camera_calibration (cameracalibrator.py, "ost.yaml"). */
static const char ros_file[] =
    "image_width: 2448\n"
    "image_height: 2048\n"
    "camera_name: narrow_stereo\n"
    "camera_matrix:\n"
    "  rows: 3\n"
    "  cols: 3\n"
    "  data: [3478.26087, 0.     , 1223.5, 0.     , 3480.1, 1023.5, 0.     , 0.     , 1.     ]\n"
    "distortion_model: plumb_bob\n"
    "distortion_coefficients:\n"
    "  rows: 1\n"
    "  cols: 5\n"
    "  data: [-0.091, 0.12, 0.0005, -0.0003, 0.000000]\n"
    "rectification_matrix:\n"
    "  rows: 3\n"
    "  cols: 3\n"
    "  data: [1., 0., 0., 0., 1., 0., 0., 0., 1.]\n"
    "projection_matrix:\n"
    "  rows: 3\n"
    "  cols: 4\n"
    "  data: [3478.26087, 0., 1223.5, 0., 0., 3480.1, 1023.5, 0., 0., 0., 1., 0.]\n";

static void reads_ros_file(void **state)
{
    cdsp_camera cam;
    cdsp_host_err err;
    const char *path = tt_path("ost.yaml");
    (void)state;
    tt_write_str(path, ros_file);
    assert_int_equal(cdsp_host_calib_read(path, &cam, &err), 0);
    assert_int_equal(cam.width, 2448);
    assert_int_equal(cam.height, 2048);
    assert_true(cam.fx == 3478.26087);
    assert_true(cam.fy == 3480.1);
    assert_true(cam.cx == 1223.5);
    assert_true(cam.cy == 1023.5);
    assert_true(cam.k1 == -0.091);
    assert_true(cam.k2 == 0.12);
    assert_true(cam.p1 == 0.0005);
    assert_true(cam.p2 == -0.0003);
    assert_true(cam.k3 == 0.0);
}

/* k1 k2 p1 p2 as OpenCV and some ROS drivers write them: k3 is zero. */
static void reads_four_coefficients(void **state)
{
    static const char text[] =
        "image_width: 640\nimage_height: 480\n"
        "camera_matrix: {rows: 3, cols: 3, data: [800, 0, 319.5, 0, 800, 239.5, 0, 0, 1]}\n"
        "distortion_model: plumb_bob\n"
        "distortion_coefficients: {rows: 1, cols: 4, data: [-0.12, 0.03, 0.001, -0.002]}\n";
    cdsp_camera cam;
    cdsp_host_err err;
    (void)state;
    cam.k3 = 99;
    assert_int_equal(cdsp_host_calib_parse(text, strlen(text), "four.yaml", &cam, &err), 0);
    assert_true(cam.k1 == -0.12);
    assert_true(cam.k2 == 0.03);
    assert_true(cam.p1 == 0.001);
    assert_true(cam.p2 == -0.002);
    assert_true(cam.k3 == 0.0);
}

static void block_style_and_comments(void **state)
{
    static const char text[] =
        "# written by hand\n"
        "image_height: 480   # rows\n"
        "image_width: 640\n"
        "camera_matrix:\n"
        "  data:\n"
        "    - 500\n    - 0\n    - 319.5\n    - 0\n    - 500\n    - 239.5\n"
        "    - 0\n    - 0\n    - 1\n"
        "distortion_model: plumb_bob\n"
        "distortion_coefficients: {data: [0, 0, 0, 0, 0]}\n";
    cdsp_camera cam;
    cdsp_host_err err;
    (void)state;
    assert_int_equal(cdsp_host_calib_parse(text, strlen(text), "hand.yaml", &cam, &err), 0);
    assert_int_equal(cam.width, 640);
    assert_true(cam.cx == 319.5);
}

static void write_read_roundtrip(void **state)
{
    cdsp_camera a, b;
    cdsp_host_err err;
    const char *path = tt_path("rt.yaml");
    (void)state;
    a.fx = 3478.2608695652175;
    a.fy = 3478.2608695652175 * (1 + 1e-9);
    a.cx = 1223.5;
    a.cy = 1023.4999999999;
    a.k1 = -0.1;
    a.k2 = 0.0123456789012345678;
    a.p1 = 1e-17;
    a.p2 = -3e-5;
    a.k3 = 0;
    a.width = 2448;
    a.height = 2048;
    assert_int_equal(cdsp_host_calib_write(path, &a, "my cam\"; rm", &err), 0);
    assert_int_equal(cdsp_host_calib_read(path, &b, &err), 0);
    assert_memory_equal(&a, &b, sizeof a);
    a.fx = -1;
    assert_int_equal(cdsp_host_calib_write(path, &a, NULL, &err), CDSP_HOST_E_FORMAT);
}

/* The stream writer cdsp_calib uses: its comment lines first, the
 * projection matrix it gives, and every number a YAML float (with a '.'),
 * the whole read back by the reader to the same camera. */
static void write_stream_layout(void **state)
{
    static const double P[12] = {1049.6875, 0, 515.090109501034, 0, 0, 1065.3953857421875,
                                 380.00567687148214, 0, 0, 0, 1, 0};
    cdsp_camera a, b;
    cdsp_host_err err;
    const char *path = tt_path("stream.yaml");
    char *text;
    size_t len;
    FILE *f;
    (void)state;
    memset(&a, 0, sizeof a);
    a.fx = 1099.9233091582812;
    a.fy = 1094.9052438232538;
    a.cx = 515.2955174558851;
    a.cy = 380.67460706141213;
    a.k1 = -0.2098985805018981;
    a.k2 = 1e20;
    a.width = 1024;
    a.height = 768;
    f = fopen(path, "w");
    assert_non_null(f);
    assert_int_equal(cdsp_host_calib_write_stream(f, path, &a, "camera", "first line\nsecond", P,
                                                  &err),
                     CDSP_HOST_OK);
    assert_int_equal(fclose(f), 0);
    assert_int_equal(cdsp_host_read_file(path, 1 << 16, (void **)&text, &len, &err), 0);
    {
        static const char head[] = "# first line\n# second\nimage_width: 1024\n";
        assert_true(strncmp(text, head, strlen(head)) == 0);
    }
    tt_assert_contains(text, "  data: [1099.9233091582812, 0.0, 515.2955174558851, 0.0, "
                             "1094.9052438232538, 380.67460706141213, 0.0, 0.0, 1.0]\n");
    tt_assert_contains(text, "  data: [-0.2098985805018981, 1.0e+20, 0.0, 0.0, 0.0]\n");
    tt_assert_contains(text, "  data: [1049.6875, 0.0, 515.090109501034, 0.0, 0.0, "
                             "1065.3953857421875, 380.00567687148214, 0.0, 0.0, 0.0, 1.0, 0.0]\n");
    assert_int_equal(cdsp_host_calib_parse(text, len, path, &b, &err), 0);
    assert_memory_equal(&a, &b, sizeof a);
    free(text);
}

/* A valid file with one line replaced (or removed when with == NULL). */
static char *edit(const char *field_line, const char *with)
{
    static char out[4096];
    const char *at = strstr(ros_file, field_line);
    size_t pre;
    const char *eol;
    assert_non_null(at);
    pre = (size_t)(at - ros_file);
    eol = strchr(at, '\n') + 1;
    snprintf(out, sizeof out, "%.*s%s%s", (int)pre, ros_file, with ? with : "", eol);
    return out;
}

static void malformed_files(void **state)
{
    static const struct {
        const char *line, *with, *msg;
    } cases[] = {
        {"image_width:", NULL, "cam.yaml: image_width: missing"},
        {"image_height:", "image_height: -5\n", "cam.yaml: image_height: -5 outside 1..16384"},
        {"image_height:", "image_height: 20000\n", "image_height: 20000 outside 1..16384"},
        {"image_width:", "image_width: 640.5\n", "image_width: expected an integer"},
        {"image_width:", "image_width: wide\n", "image_width: expected a number, got \"wide\""},
        {"image_width:", "image_width: [640]\n", "image_width: expected a number, got a list"},
        {"image_width:", "image_width: 0x280\n", "image_width: expected a number"},
        {"  data: [3478.26087, 0.     , 1223.5",
         "  data: [3478.26087, 0, 1223.5, 0, 3480.1, 1023.5, 0, 0]\n",
         "cam.yaml: camera_matrix.data: expected 9 numbers, got 8"},
        {"  data: [3478.26087, 0.     , 1223.5",
         "  data: [3478.26087, 0, 1223.5, 0, .nan, 1023.5, 0, 0, 1]\n",
         "camera_matrix.data[4]: expected a number, got \".nan\""},
        {"  data: [3478.26087, 0.     , 1223.5",
         "  data: [3478.26087, 0, 1223.5, 0, 1e999, 1023.5, 0, 0, 1]\n",
         "camera_matrix.data[4]: 1e999 is not a finite number"},
        {"  data: [3478.26087, 0.     , 1223.5",
         "  data: [3478.26087, 0, 1223.5, 0, fy, 1023.5, 0, 0, 1]\n",
         "camera_matrix.data[4]: expected a number, got \"fy\""},
        {"  data: [3478.26087, 0.     , 1223.5",
         "  data: [3478.26087, 2, 1223.5, 0, 3480, 1023.5, 0, 0, 1]\n",
         "camera_matrix.data[1]: skew 2 is not supported"},
        {"  data: [3478.26087, 0.     , 1223.5",
         "  data: [-3478.26087, 0, 1223.5, 0, 3480, 1023.5, 0, 0, 1]\n",
         "focal lengths fx = -3478.26, fy = 3480 must be positive"},
        {"  data: [3478.26087, 0.     , 1223.5",
         "  data: [3478.26087, 0, 1223.5, 0, 3480, 1023.5, 0, 0, 2]\n",
         "camera_matrix.data: not a camera matrix"},
        {"  data: [3478.26087, 0.     , 1223.5", "  data: 5\n",
         "camera_matrix.data: expected a list of 9 numbers, got a scalar"},
        {"  data: [3478.26087, 0.     , 1223.5", NULL, "camera_matrix.data: missing"},
        {"camera_matrix:", "camera_matrix: 7\nunused:\n", "camera_matrix: expected a mapping"},
        {"  rows: 3\n  cols: 3\n  data: [3478", "  rows: 2\n", "camera_matrix.rows: expected 3, got 2"},
        {"distortion_model:", "distortion_model: equidistant\n",
         "distortion_model: \"equidistant\" is not supported (only plumb_bob)"},
        {"distortion_model:", NULL, "distortion_model: missing"},
        {"distortion_coefficients:", "distortion_coefficients: []\nunused:\n",
         "distortion_coefficients: expected a mapping"},
        /* 4 numbers are k1 k2 p1 p2 (reads_four_coefficients), but then the
         * declared cols: 5 disagrees */
        {"  data: [-0.091", "  data: [-0.091, 0.12, 0.0005, -0.0003]\n",
         "distortion_coefficients.cols: expected 4, got 5"},
        {"  data: [-0.091", "  data: [-0.091, 0.12, 0.0005]\n",
         "distortion_coefficients.data: expected 5 numbers, got 3"},
        {"  data: [-0.091", "  data: [-0.091, 0.12, 0.0005, -0.0003, 0, 0.01, 0.002, 0.0003]\n",
         "distortion_coefficients.data: 8 coefficients is OpenCV's rational model"},
        {"distortion_model:", "distortion_model: rational_polynomial\n",
         "distortion_model: \"rational_polynomial\" (OpenCV's rational model, 8 coefficients) "
         "is not supported"},
        {"  data: [-0.091", "  data: [-0.091, 0.12, 0.0005, -0.0003, {k3: 0}]\n",
         "distortion_coefficients.data[4]: expected a number, got a mapping"},
        {"  cols: 5\n", "  cols: 4\n", "distortion_coefficients.cols: expected 5, got 4"},
        {"camera_name:", "image_width: 640\n", "image_width: given more than once"},
        {"camera_name:", "camera_name: [unclosed\n", "YAML error at line 4"},
        {"image_width:", "\t\n", "YAML error at line 1"},
    };
    size_t i;
    const char *path = tt_path("cam.yaml");
    (void)state;
    for (i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        cdsp_camera cam;
        cdsp_host_err err;
        int rc = cdsp_host_calib_parse(edit(cases[i].line, cases[i].with),
                                       strlen(edit(cases[i].line, cases[i].with)), "cam.yaml",
                                       &cam, &err);
        if (rc != CDSP_HOST_E_FORMAT || !strstr(err.msg, cases[i].msg) ||
            strncmp(err.msg, "cam.yaml: ", 10) != 0)
            fail_msg("case %zu: rc %d, \"%s\", wanted \"%s\"", i, rc, rc ? err.msg : "",
                     cases[i].msg);
    }
    /* and through a file: the message names the path */
    tt_write_str(path, edit("image_height:", NULL));
    {
        cdsp_camera cam;
        cdsp_host_err err;
        char want[700];
        assert_int_equal(cdsp_host_calib_read(path, &cam, &err), CDSP_HOST_E_FORMAT);
        snprintf(want, sizeof want, "%s: image_height: missing", path);
        assert_string_equal(err.msg, want);
    }
}

static void not_a_calibration_at_all(void **state)
{
    static const struct {
        const char *text, *msg;
    } cases[] = {
        {"", "empty calibration file"},
        {"# only a comment\n", "empty calibration file"},
        {"- 1\n- 2\n", "expected a mapping of camera_info keys at the top, got a list"},
        {"just text", "expected a mapping of camera_info keys at the top, got a scalar"},
        {"a: [1, 2\n", "YAML error"},
        {"a: &x [1]\nb: *y\n", "YAML error"},
        {"\xc3\x28: 1\n", "YAML error"},
        /* issue 16: bounded before libyaml builds the document */
        {"a: [[[[[[[[1]]]]]]]]\n", "YAML nested deeper than 8 levels at line 1, column 11"},
        {"[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[", "YAML nested deeper than 8 levels"},
    };
    size_t i;
    (void)state;
    for (i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        cdsp_camera cam;
        cdsp_host_err err;
        int rc = cdsp_host_calib_parse(cases[i].text, strlen(cases[i].text), "x.yaml", &cam, &err);
        if (rc == 0 || !strstr(err.msg, cases[i].msg) || strncmp(err.msg, "x.yaml: ", 8) != 0)
            fail_msg("case %zu: rc %d, \"%s\"", i, rc, rc ? err.msg : "");
    }
}

static void limits_and_files(void **state)
{
    cdsp_camera cam;
    cdsp_host_err err;
    size_t n = CDSP_HOST_YAML_MAX_BYTES + 10;
    char *big = malloc(n + 1);
    (void)state;
    assert_non_null(big);
    memset(big, '#', n);
    big[n] = 0;
    tt_write(tt_path("big.yaml"), big, n);
    assert_int_equal(cdsp_host_calib_read(tt_path("big.yaml"), &cam, &err), CDSP_HOST_E_LIMIT);
    tt_assert_contains(err.msg, "exceeds the limit");
    free(big);
    assert_int_equal(cdsp_host_calib_read(tt_path("none.yaml"), &cam, &err), CDSP_HOST_E_IO);
    tt_assert_contains(err.msg, "none.yaml: cannot open");
    /* aliases are shared nodes, not copies: a "billion laughs" file is small
     * and is refused by the schema, not expanded */
    {
        static const char laughs[] =
            "a: &a [1, 1, 1, 1, 1, 1, 1, 1, 1]\n"
            "b: &b [*a, *a, *a, *a, *a, *a, *a, *a, *a]\n"
            "c: &c [*b, *b, *b, *b, *b, *b, *b, *b, *b]\n"
            "d: &d [*c, *c, *c, *c, *c, *c, *c, *c, *c]\n"
            "camera_matrix: {data: *d}\n";
        assert_int_equal(cdsp_host_calib_parse(laughs, strlen(laughs), "l.yaml", &cam, &err),
                         CDSP_HOST_E_FORMAT);
        tt_assert_contains(err.msg, "l.yaml: image_width: missing");
    }
}

static void size_mismatch(void **state)
{
    cdsp_camera cam;
    cdsp_host_err err;
    (void)state;
    cam.width = 2448;
    cam.height = 2048;
    assert_int_equal(cdsp_host_calib_match(&cam, "cam.yaml", 2448, 2048, "f.pgm", &err), 0);
    assert_int_equal(cdsp_host_calib_match(&cam, "cam.yaml", 640, 480, "f.pgm", &err),
                     CDSP_HOST_E_MISMATCH);
    assert_string_equal(err.msg, "f.pgm: image is 640x480 but cam.yaml is for 2448x2048");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(reads_ros_file),
        cmocka_unit_test(reads_four_coefficients),
        cmocka_unit_test(block_style_and_comments),
        cmocka_unit_test(write_read_roundtrip),
        cmocka_unit_test(write_stream_layout),
        cmocka_unit_test(malformed_files),
        cmocka_unit_test(not_a_calibration_at_all),
        cmocka_unit_test(limits_and_files),
        cmocka_unit_test(size_mismatch),
    };
    return cmocka_run_group_tests_name("host_calib", tests, NULL, tt_teardown);
}
