/*
 * test_host_json.c - the JSON writer and the pose record, read back by a
 * real parser (json-c): escaping, UTF-8 repair, exact numbers, overflow,
 * and the record's field names and values.
 */
#define _POSIX_C_SOURCE 200809L
#include "tool_test.h"

#include <json-c/json.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>

#include "cdsp_host.h"

static json_object *parse(const char *text)
{
    json_tokener *tok = json_tokener_new();
    json_object *o;
    assert_non_null(text);
    json_tokener_set_flags(tok, JSON_TOKENER_STRICT | JSON_TOKENER_VALIDATE_UTF8);
    o = json_tokener_parse_ex(tok, text, (int)strlen(text));
    if (!o || json_tokener_get_error(tok) != json_tokener_success ||
        (size_t)json_tokener_get_parse_end(tok) != strlen(text))
        fail_msg("not one JSON value: %s", text);
    json_tokener_free(tok);
    return o;
}

static json_object *get(json_object *o, const char *key)
{
    json_object *v = NULL;
    if (!json_object_object_get_ex(o, key, &v))
        fail_msg("no key \"%s\" in %s", key, json_object_to_json_string(o));
    return v;
}

static void strings_escaped_and_repaired(void **state)
{
    static const struct {
        const char *in, *out;
    } cases[] = {
        {"plain", "plain"},
        {"quote \" backslash \\ slash /", "quote \" backslash \\ slash /"},
        {"tab\tnl\ncr\rbs\bff\f", "tab\tnl\ncr\rbs\bff\f"},
        {"ctl \x01\x1f end", "ctl \x01\x1f end"},
        {"utf8 \xc3\xa9 \xe2\x82\xac \xf0\x9f\x98\x80", "utf8 \xc3\xa9 \xe2\x82\xac \xf0\x9f\x98\x80"},
        {"bad \xff x", "bad \xef\xbf\xbd x"},
        {"overlong \xc0\xaf", "overlong \xef\xbf\xbd\xef\xbf\xbd"},
        {"surrogate \xed\xa0\x80", "surrogate \xef\xbf\xbd\xef\xbf\xbd\xef\xbf\xbd"},
        {"cut \xe2\x82", "cut \xef\xbf\xbd\xef\xbf\xbd"},
        {"", ""},
    };
    size_t i;
    (void)state;
    for (i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char buf[256];
        cdsp_host_json j;
        json_object *o;
        cdsp_host_json_init(&j, buf, sizeof buf);
        cdsp_host_json_begin_object(&j);
        cdsp_host_json_key(&j, cases[i].in);
        cdsp_host_json_string(&j, cases[i].in);
        cdsp_host_json_end_object(&j);
        o = parse(cdsp_host_json_finish(&j));
        assert_string_equal(json_object_get_string(get(o, cases[i].out)), cases[i].out);
        json_object_put(o);
    }
}

static void numbers_exact(void **state)
{
    cdsp_rng rng;
    int i;
    (void)state;
    cdsp_rng_seed(&rng, 7, 3);
    for (i = 0; i < 2000; i++) {
        char buf[128];
        cdsp_host_json j;
        json_object *o;
        double v;
        uint64_t bits = ((uint64_t)cdsp_rng_u32(&rng) << 32) | cdsp_rng_u32(&rng);
        memcpy(&v, &bits, sizeof v);
        if (i < 10) {
            static const double special[10] = {0.0, -0.0, 1.0, 0.1, 1e-300, 5e-324, 1.7976931348623157e308,
                                               3478.2608695652175, -2.5, 123456789.0};
            v = special[i];
        }
        if (!isfinite(v))
            continue;
        cdsp_host_json_init(&j, buf, sizeof buf);
        cdsp_host_json_begin_array(&j);
        cdsp_host_json_number(&j, v);
        cdsp_host_json_end_array(&j);
        o = parse(cdsp_host_json_finish(&j));
        assert_true(json_object_get_double(json_object_array_get_idx(o, 0)) == v);
        json_object_put(o);
    }
}

static void nonfinite_is_null_and_structure(void **state)
{
    char buf[256];
    cdsp_host_json j;
    json_object *o, *a;
    (void)state;
    cdsp_host_json_init(&j, buf, sizeof buf);
    cdsp_host_json_begin_object(&j);
    cdsp_host_json_key(&j, "nan");
    cdsp_host_json_number(&j, NAN);
    cdsp_host_json_key(&j, "inf");
    cdsp_host_json_number(&j, -INFINITY);
    cdsp_host_json_key(&j, "list");
    cdsp_host_json_begin_array(&j);
    cdsp_host_json_int(&j, -42);
    cdsp_host_json_bool(&j, 1);
    cdsp_host_json_null(&j);
    cdsp_host_json_begin_object(&j);
    cdsp_host_json_end_object(&j);
    cdsp_host_json_begin_array(&j);
    cdsp_host_json_end_array(&j);
    cdsp_host_json_end_array(&j);
    cdsp_host_json_end_object(&j);
    o = parse(cdsp_host_json_finish(&j));
    assert_true(json_object_is_type(get(o, "nan"), json_type_null));
    assert_true(json_object_is_type(get(o, "inf"), json_type_null));
    a = get(o, "list");
    assert_int_equal(json_object_array_length(a), 5);
    assert_int_equal(json_object_get_int(json_object_array_get_idx(a, 0)), -42);
    assert_true(json_object_get_boolean(json_object_array_get_idx(a, 1)));
    json_object_put(o);
}

static void overflow_and_misuse(void **state)
{
    char buf[64];
    cdsp_host_json j;
    size_t cap;
    int d;
    (void)state;
    /* every capacity from 0 up: never writes past cap, finish NULL until it fits */
    for (cap = 0; cap < 40; cap++) {
        memset(buf, 'Z', sizeof buf);
        cdsp_host_json_init(&j, buf, cap);
        cdsp_host_json_begin_object(&j);
        cdsp_host_json_key(&j, "frame");
        cdsp_host_json_string(&j, "some/long/path.pgm");
        cdsp_host_json_end_object(&j);
        if (cap < 31)
            assert_null(cdsp_host_json_finish(&j));
        else
            assert_string_equal(cdsp_host_json_finish(&j), "{\"frame\":\"some/long/path.pgm\"}");
        assert_int_equal(buf[cap], 'Z');
    }
    /* unbalanced or too deep */
    cdsp_host_json_init(&j, buf, sizeof buf);
    cdsp_host_json_begin_object(&j);
    assert_null(cdsp_host_json_finish(&j));
    cdsp_host_json_init(&j, buf, sizeof buf);
    cdsp_host_json_end_array(&j);
    assert_null(cdsp_host_json_finish(&j));
    cdsp_host_json_init(&j, buf, sizeof buf);
    for (d = 0; d < CDSP_HOST_JSON_DEPTH + 1; d++)
        cdsp_host_json_begin_array(&j);
    for (d = 0; d < CDSP_HOST_JSON_DEPTH + 1; d++)
        cdsp_host_json_end_array(&j);
    assert_null(cdsp_host_json_finish(&j));
    cdsp_host_json_init(&j, buf, sizeof buf);
    cdsp_host_json_begin_object(&j);
    cdsp_host_json_key(&j, "a");
    cdsp_host_json_end_object(&j);
    assert_null(cdsp_host_json_finish(&j));
}

static void check_vec(json_object *a, const cdsp_real *want, int n)
{
    int i;
    assert_true(json_object_is_type(a, json_type_array));
    assert_int_equal(json_object_array_length(a), n);
    for (i = 0; i < n; i++)
        assert_true(json_object_get_double(json_object_array_get_idx(a, (size_t)i)) ==
                    (double)want[i]);
}

static void pose_record(void **state)
{
    cdsp_result r;
    char buf[4096];
    cdsp_host_json j;
    json_object *o, *s;
    int i, k;
    (void)state;
    memset(&r, 0, sizeof r);
    for (i = 0; i < 3; i++) {
        r.point[i] = 10.5 * (i + 1);
        r.direction[i] = i == 1 ? 1.0 : 0.0;
        r.sigma_point[i] = 0.01 * (i + 1);
        r.sigma_direction[i] = 1e-4 * (i + 1);
        for (k = 0; k < 2; k++) {
            r.lines[k][i] = 0.3 * (i + 1) + k;
            r.segment[k][i] = r.point[i] + (k ? 50.0 : -50.0) * r.direction[i];
        }
    }
    r.distance = 37.6;
    r.alpha = 0.42;
    r.sigma_distance = 0.02;
    r.inliers[0] = 812;
    r.inliers[1] = 799;
    r.rms[0] = 0.05;
    r.rms[1] = 0.06;
    r.n_edges = 2000;
    r.flags = CDSP_FLAG_TRACKED;

    cdsp_host_json_init(&j, buf, sizeof buf);
    cdsp_host_json_begin_object(&j);
    cdsp_host_json_key(&j, "frame");
    cdsp_host_json_string(&j, "a.pgm");
    cdsp_host_json_pose(&j, CDSP_OK, NULL, &r, 8.0);
    cdsp_host_json_end_object(&j);
    o = parse(cdsp_host_json_finish(&j));
    assert_string_equal(json_object_get_string(get(o, "status")), "ok");
    assert_false(json_object_object_get_ex(o, "error", NULL));
    assert_true(json_object_get_double(get(o, "radius")) == 8.0);
    check_vec(get(o, "point"), r.point, 3);
    check_vec(get(o, "direction"), r.direction, 3);
    assert_true(json_object_get_double(get(o, "distance")) == r.distance);
    check_vec(json_object_array_get_idx(get(o, "lines"), 0), r.lines[0], 3);
    check_vec(json_object_array_get_idx(get(o, "lines"), 1), r.lines[1], 3);
    check_vec(json_object_array_get_idx(get(o, "segment"), 1), r.segment[1], 3);
    assert_int_equal(json_object_get_int(json_object_array_get_idx(get(o, "inliers"), 0)), 812);
    assert_int_equal(json_object_get_int(json_object_array_get_idx(get(o, "inliers"), 1)), 799);
    s = get(o, "sigma");
    check_vec(get(s, "point"), r.sigma_point, 3);
    check_vec(get(s, "direction"), r.sigma_direction, 3);
    assert_true(json_object_get_double(get(s, "distance")) == r.sigma_distance);
    assert_true(json_object_get_boolean(get(o, "tracked")));
    assert_false(json_object_get_boolean(get(o, "truncated")));
    assert_int_equal(json_object_get_int(get(o, "edges")), 2000);
    json_object_put(o);

    /* error record: status, error token, no pose */
    cdsp_host_json_init(&j, buf, sizeof buf);
    cdsp_host_json_begin_object(&j);
    cdsp_host_json_pose(&j, CDSP_E_NO_PIPE, NULL, NULL, 8.0);
    cdsp_host_json_end_object(&j);
    o = parse(cdsp_host_json_finish(&j));
    assert_string_equal(json_object_get_string(get(o, "status")), "error");
    assert_string_equal(json_object_get_string(get(o, "error")), "no-pipe");
    assert_false(json_object_object_get_ex(o, "point", NULL));
    json_object_put(o);
    cdsp_host_json_init(&j, buf, sizeof buf);
    cdsp_host_json_begin_object(&j);
    cdsp_host_json_pose(&j, CDSP_E_FORMAT, "bad-frame", NULL, 8.0);
    cdsp_host_json_end_object(&j);
    o = parse(cdsp_host_json_finish(&j));
    assert_string_equal(json_object_get_string(get(o, "error")), "bad-frame");
    json_object_put(o);
}

/* The worst case fits CDSP_HOST_JSON_POSE_MAX: every number at its
 * longest text, the counts at their largest. */
static void pose_record_bound(void **state)
{
    cdsp_result r;
    char buf[CDSP_HOST_JSON_POSE_MAX + 2];
    cdsp_host_json j;
    cdsp_real *p = (cdsp_real *)(void *)&r;
    size_t i;
    (void)state;
    memset(&r, 0, sizeof r);
    /* fill every real of the result (the struct starts with reals) */
    for (i = 0; i < offsetof(cdsp_result, rms) / sizeof(cdsp_real); i++)
        p[i] = -1.2345678901234567e-300;
    r.rms[0] = r.rms[1] = -1.2345678901234567e-300;
    r.inliers[0] = r.inliers[1] = r.n_edges = UINT32_MAX;
    r.flags = CDSP_FLAG_TRACKED | CDSP_FLAG_TRUNCATED;
    cdsp_host_json_init(&j, buf, sizeof buf);
    cdsp_host_json_begin_object(&j);
    cdsp_host_json_pose(&j, CDSP_OK, NULL, &r, (cdsp_real)-1.2345678901234567e-300);
    cdsp_host_json_end_object(&j);
    assert_non_null(cdsp_host_json_finish(&j));
    assert_true(strlen(buf) - 2 <= CDSP_HOST_JSON_POSE_MAX); /* without the braces */
    json_object_put(parse(buf));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(strings_escaped_and_repaired),
        cmocka_unit_test(numbers_exact),
        cmocka_unit_test(nonfinite_is_null_and_structure),
        cmocka_unit_test(overflow_and_misuse),
        cmocka_unit_test(pose_record),
        cmocka_unit_test(pose_record_bound),
    };
    return cmocka_run_group_tests_name("host_json", tests, NULL, NULL);
}
