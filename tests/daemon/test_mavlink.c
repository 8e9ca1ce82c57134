/*
 * test_mavlink.c - the MAVLink 2 codec (daemon/mavlink.c) against the
 * protocol specification:
 *   - CRC-16/MCRF4XX: the catalogue check value ("123456789" -> 0x6F91) and
 *     random buffers against the bit-serial definition written out here;
 *   - CRC_EXTRA: computed here from each message's field list by the
 *     specification's rule (crc of "NAME " then "type name " per base field
 *     in wire order, the array length byte for arrays; low ^ high byte),
 *     compared with the module and with the table of docs/mavlink.md (and
 *     /work/shared/FACTS.md when that file is there);
 *   - three frames whose bytes were worked out by hand from the wire rules
 *     (field order, little endian, IEEE 754 floats, trailing-zero
 *     truncation; the two crc bytes with the bit-serial definition):
 *     encoding gives exactly those bytes, decoding them gives the message;
 *   - the stream decoder: junk before a frame, split frames, a flipped bit
 *     (crc rejected), unknown ids, signed frames' length.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "mavlink.h"

/* The definition: shift each bit through the reflected register. */
static uint16_t crc_bitwise(uint16_t c, const uint8_t *p, size_t n)
{
    size_t i;
    int b;
    for (i = 0; i < n; i++) {
        c ^= p[i];
        for (b = 0; b < 8; b++)
            c = (c & 1) ? (uint16_t)((c >> 1) ^ 0x8408) : (uint16_t)(c >> 1);
    }
    return c;
}

static void test_crc(void **state)
{
    static const uint8_t check[] = "123456789";
    uint8_t buf[300];
    uint32_t x = 12345;
    int t;
    size_t i;
    (void)state;
    assert_int_equal(cdspd_mavlink_crc(0xFFFF, check, 9), 0x6F91);
    assert_int_equal(crc_bitwise(0xFFFF, check, 9), 0x6F91);
    for (t = 0; t < 50; t++) {
        size_t n = (size_t)t * 6;
        for (i = 0; i < n; i++) {
            x = x * 1103515245u + 12345u;
            buf[i] = (uint8_t)(x >> 16);
        }
        assert_int_equal(cdspd_mavlink_crc(0xFFFF, buf, n), crc_bitwise(0xFFFF, buf, n));
    }
}

/* ---- CRC_EXTRA from the message definitions ---------------------------- */
typedef struct {
    const char *type, *name;
    int array;
} field;

typedef struct {
    const char *name;
    uint32_t id;
    const field *fields; /* base fields in wire order, NULL-terminated */
} message;

static const field hb_fields[] = {{"uint32_t", "custom_mode", 0},  {"uint8_t", "type", 0},
                                  {"uint8_t", "autopilot", 0},     {"uint8_t", "base_mode", 0},
                                  {"uint8_t", "system_status", 0}, {"uint8_t", "mavlink_version", 0},
                                  {NULL, NULL, 0}};
static const field lt_fields[] = {{"uint64_t", "time_usec", 0}, {"float", "angle_x", 0},
                                  {"float", "angle_y", 0},      {"float", "distance", 0},
                                  {"float", "size_x", 0},       {"float", "size_y", 0},
                                  {"uint8_t", "target_num", 0}, {"uint8_t", "frame", 0},
                                  {NULL, NULL, 0}};
static const field dv_fields[] = {{"uint64_t", "time_usec", 0}, {"float", "x", 0}, {"float", "y", 0},
                                  {"float", "z", 0}, {"char", "name", 10}, {NULL, NULL, 0}};
static const field nvf_fields[] = {{"uint32_t", "time_boot_ms", 0}, {"float", "value", 0},
                                   {"char", "name", 10}, {NULL, NULL, 0}};
static const message messages[] = {
    {"HEARTBEAT", CDSPD_MAVLINK_ID_HEARTBEAT, hb_fields},
    {"LANDING_TARGET", CDSPD_MAVLINK_ID_LANDING_TARGET, lt_fields},
    {"DEBUG_VECT", CDSPD_MAVLINK_ID_DEBUG_VECT, dv_fields},
    {"NAMED_VALUE_FLOAT", CDSPD_MAVLINK_ID_NAMED_VALUE_FLOAT, nvf_fields},
};
#define N_MESSAGES (sizeof messages / sizeof messages[0])

static uint16_t crc_str(uint16_t c, const char *s)
{
    c = crc_bitwise(c, (const uint8_t *)s, strlen(s));
    return crc_bitwise(c, (const uint8_t *)" ", 1);
}

static int extra_of(const message *m)
{
    uint16_t c = crc_str(0xFFFF, m->name);
    const field *f;
    for (f = m->fields; f->type; f++) {
        c = crc_str(c, f->type);
        c = crc_str(c, f->name);
        if (f->array) {
            uint8_t a = (uint8_t)f->array;
            c = crc_bitwise(c, &a, 1);
        }
    }
    return (c & 0xFF) ^ (c >> 8);
}

/* The CRC_EXTRA column of a markdown table "| NAME | id | extra | ..." in
 * path; -1 when the file or the row is missing. */
static int table_extra(const char *path, const char *name, long *id)
{
    FILE *f = fopen(path, "r");
    char line[1024], want[64];
    int extra = -1;
    if (!f)
        return -1;
    snprintf(want, sizeof want, "| %s |", name);
    while (fgets(line, sizeof line, f)) {
        long i, e;
        if (strncmp(line, want, strlen(want)))
            continue;
        if (sscanf(line + strlen(want), " %ld | %ld |", &i, &e) == 2) {
            *id = i;
            extra = (int)e;
        }
        break;
    }
    fclose(f);
    return extra;
}

static void test_crc_extra(void **state)
{
    size_t i;
    (void)state;
    for (i = 0; i < N_MESSAGES; i++) {
        const message *m = &messages[i];
        int want = extra_of(m), doc;
        long id = -1;
        assert_int_equal(cdspd_mavlink_crc_extra(m->id), want);
        doc = table_extra("docs/mavlink.md", m->name, &id);
        if (doc < 0)
            fail_msg("docs/mavlink.md has no row '| %s | id | CRC_EXTRA |' (run from the top)",
                     m->name);
        assert_int_equal(doc, want);
        assert_int_equal(id, (long)m->id);
        id = -1;
        doc = table_extra("/work/shared/FACTS.md", m->name, &id);
        if (doc >= 0) {
            assert_int_equal(doc, want);
            assert_int_equal(id, (long)m->id);
        }
    }
    assert_int_equal(cdspd_mavlink_crc_extra(1), -1);
}

/* ---- frames worked out by hand ------------------------------------------ */
/* HEARTBEAT seq 0, sys 1, comp 191: custom_mode 0 (4 bytes), type 18,
 * autopilot 8, base_mode 0, system_status 4 (ACTIVE), mavlink_version 3.
 * The last byte is not zero: all 9 sent. */
static const uint8_t hb_bytes[] = {0xFD, 0x09, 0x00, 0x00, 0x00, 0x01, 0xBF, 0x00, 0x00, 0x00,
                                   0x00, 0x00, 0x00, 0x00, 0x12, 0x08, 0x00, 0x04, 0x03,
                                   0xAE, 0xC6};
/* LANDING_TARGET seq 7: time_usec 1000000 = 0x0F4240; angle_x 0.25
 * (0x3E800000), angle_y -0.5 (0xBF000000), distance 2 (0x40000000), size_x
 * 0.125 (0x3E000000), size_y 0.0625 (0x3D800000), target_num 0, frame 12;
 * extensions x 1.5 (0x3FC00000), y -0.25 (0xBE800000), z 2, q (1, 0, 0, 0)
 * (1 = 0x3F800000), type 3, position_valid 1: 60 bytes, none dropped. */
static const uint8_t lt_bytes[] = {
    0xFD, 0x3C, 0x00, 0x00, 0x07, 0x01, 0xBF, 0x95, 0x00, 0x00,
    0x40, 0x42, 0x0F, 0x00, 0x00, 0x00, 0x00, 0x00, /* time_usec */
    0x00, 0x00, 0x80, 0x3E, 0x00, 0x00, 0x00, 0xBF, /* angle_x, angle_y */
    0x00, 0x00, 0x00, 0x40, 0x00, 0x00, 0x00, 0x3E, /* distance, size_x */
    0x00, 0x00, 0x80, 0x3D, 0x00, 0x0C,             /* size_y, target_num, frame */
    0x00, 0x00, 0xC0, 0x3F, 0x00, 0x00, 0x80, 0xBE, 0x00, 0x00, 0x00, 0x40, /* x, y, z */
    0x00, 0x00, 0x80, 0x3F, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
    0x00, 0x00, 0x00, 0x00,                         /* q */
    0x03, 0x01,                                     /* type, position_valid */
    0xF5, 0x55};
/* DEBUG_VECT seq 200: time_usec 1000000, x 0.5 (0x3F000000), y -1
 * (0xBF800000), z 0, name "PIPE_DIR" + two NULs: the two trailing zeros
 * are dropped, len 28. */
static const uint8_t dv_bytes[] = {0xFD, 0x1C, 0x00, 0x00, 0xC8, 0x01, 0xBF, 0xFA, 0x00, 0x00,
                                   0x40, 0x42, 0x0F, 0x00, 0x00, 0x00, 0x00, 0x00,
                                   0x00, 0x00, 0x00, 0x3F, 0x00, 0x00, 0x80, 0xBF,
                                   0x00, 0x00, 0x00, 0x00,
                                   0x50, 0x49, 0x50, 0x45, 0x5F, 0x44, 0x49, 0x52,
                                   0x91, 0x92};

static void check_bytes(const uint8_t *got, size_t n, const uint8_t *want, size_t wn)
{
    size_t i;
    assert_int_equal(n, wn);
    for (i = 0; i < n; i++)
        if (got[i] != want[i])
            fail_msg("byte %zu: 0x%02X, expected 0x%02X", i, got[i], want[i]);
}

static void test_heartbeat_vector(void **state)
{
    cdspd_mavlink_heartbeat m = {0, 18, 8, 0, 4, 3}, back;
    cdspd_mavlink_frame f;
    uint8_t pl[CDSPD_MAVLINK_LEN_HEARTBEAT], out[CDSPD_MAVLINK_MAX_FRAME];
    size_t n, used;
    (void)state;
    assert_int_equal(cdspd_mavlink_pack_heartbeat(pl, &m), CDSPD_MAVLINK_LEN_HEARTBEAT);
    n = cdspd_mavlink_frame_encode(out, sizeof out, 0, 1, 191, CDSPD_MAVLINK_ID_HEARTBEAT, pl,
                                   sizeof pl);
    check_bytes(out, n, hb_bytes, sizeof hb_bytes);
    assert_int_equal(cdspd_mavlink_frame_decode(hb_bytes, sizeof hb_bytes, &f, &used),
                     CDSPD_MAVLINK_OK);
    assert_int_equal(used, sizeof hb_bytes);
    assert_int_equal(f.sysid, 1);
    assert_int_equal(f.compid, 191);
    assert_int_equal(f.seq, 0);
    assert_int_equal(cdspd_mavlink_unpack_heartbeat(&f, &back), 0);
    assert_int_equal(back.custom_mode, 0);
    assert_int_equal(back.type, 18);
    assert_int_equal(back.autopilot, 8);
    assert_int_equal(back.base_mode, 0);
    assert_int_equal(back.system_status, 4);
    assert_int_equal(back.mavlink_version, 3);
    assert_int_equal(cdspd_mavlink_unpack_landing_target(&f, NULL), -1);
}

static void test_landing_target_vector(void **state)
{
    cdspd_mavlink_landing_target m, back;
    cdspd_mavlink_frame f;
    uint8_t pl[CDSPD_MAVLINK_LEN_LANDING_TARGET], out[CDSPD_MAVLINK_MAX_FRAME];
    size_t n, used;
    int i;
    (void)state;
    memset(&m, 0, sizeof m);
    m.time_usec = 1000000;
    m.angle_x = 0.25f;
    m.angle_y = -0.5f;
    m.distance = 2;
    m.size_x = 0.125f;
    m.size_y = 0.0625f;
    m.frame = 12;
    m.x = 1.5f;
    m.y = -0.25f;
    m.z = 2;
    m.q[0] = 1;
    m.type = 3;
    m.position_valid = 1;
    assert_int_equal(cdspd_mavlink_pack_landing_target(pl, &m), CDSPD_MAVLINK_LEN_LANDING_TARGET);
    n = cdspd_mavlink_frame_encode(out, sizeof out, 7, 1, 191, CDSPD_MAVLINK_ID_LANDING_TARGET, pl,
                                   sizeof pl);
    check_bytes(out, n, lt_bytes, sizeof lt_bytes);
    assert_int_equal(cdspd_mavlink_frame_decode(lt_bytes, sizeof lt_bytes, &f, &used),
                     CDSPD_MAVLINK_OK);
    assert_int_equal(f.msgid, 149);
    assert_int_equal(f.seq, 7);
    assert_int_equal(cdspd_mavlink_unpack_landing_target(&f, &back), 0);
    assert_true(back.time_usec == 1000000);
    assert_true(back.angle_x == 0.25f && back.angle_y == -0.5f && back.distance == 2.0f);
    assert_true(back.size_x == 0.125f && back.size_y == 0.0625f);
    assert_int_equal(back.target_num, 0);
    assert_int_equal(back.frame, 12);
    assert_true(back.x == 1.5f && back.y == -0.25f && back.z == 2.0f);
    assert_true(back.q[0] == 1.0f);
    for (i = 1; i < 4; i++)
        assert_true(back.q[i] == 0.0f);
    assert_int_equal(back.type, 3);
    assert_int_equal(back.position_valid, 1);
}

static void test_debug_vect_truncation(void **state)
{
    cdspd_mavlink_debug_vect m, back;
    cdspd_mavlink_frame f;
    uint8_t pl[CDSPD_MAVLINK_LEN_DEBUG_VECT], out[CDSPD_MAVLINK_MAX_FRAME];
    size_t n, used;
    (void)state;
    memset(&m, 0, sizeof m);
    m.time_usec = 1000000;
    m.x = 0.5f;
    m.y = -1.0f;
    memcpy(m.name, "PIPE_DIR", 8);
    assert_int_equal(cdspd_mavlink_pack_debug_vect(pl, &m), CDSPD_MAVLINK_LEN_DEBUG_VECT);
    n = cdspd_mavlink_frame_encode(out, sizeof out, 200, 1, 191, CDSPD_MAVLINK_ID_DEBUG_VECT, pl,
                                   sizeof pl);
    check_bytes(out, n, dv_bytes, sizeof dv_bytes);
    assert_int_equal(cdspd_mavlink_frame_decode(dv_bytes, sizeof dv_bytes, &f, &used),
                     CDSPD_MAVLINK_OK);
    assert_int_equal(f.len, 28);
    memset(&back, 0x55, sizeof back);
    assert_int_equal(cdspd_mavlink_unpack_debug_vect(&f, &back), 0);
    assert_true(back.x == 0.5f && back.y == -1.0f && back.z == 0.0f);
    assert_memory_equal(back.name, "PIPE_DIR\0\0", 10); /* the dropped tail reads as zeros */
    /* an all-zero payload keeps one byte */
    memset(pl, 0, sizeof pl);
    n = cdspd_mavlink_frame_encode(out, sizeof out, 0, 1, 1, CDSPD_MAVLINK_ID_DEBUG_VECT, pl,
                                   sizeof pl);
    assert_int_equal(n, CDSPD_MAVLINK_HEADER + 1 + 2);
    assert_int_equal(out[1], 1);
    /* too small an output, an unknown id, an oversized payload */
    assert_int_equal(cdspd_mavlink_frame_encode(out, sizeof hb_bytes - 1, 0, 1, 191, 0, hb_bytes + 10,
                                                9),
                     0);
    assert_int_equal(cdspd_mavlink_frame_encode(out, sizeof out, 0, 1, 191, 77, pl, 5), 0);
    assert_int_equal(cdspd_mavlink_frame_encode(out, sizeof out, 0, 1, 191, 0, pl, 256), 0);
}

static void test_stream(void **state)
{
    uint8_t buf[512];
    size_t n = 0, used, off = 0;
    cdspd_mavlink_frame f;
    int got_ok = 0, junk = 0, bad = 0, unknown = 0;
    static const uint8_t noise[] = {0x00, 0x11, 0xFE, 0x22};
    (void)state;
    /* noise, heartbeat, a landing target with one bit flipped, a frame of
     * an unknown id (77), a debug vector */
    memcpy(buf + n, noise, sizeof noise);
    n += sizeof noise;
    memcpy(buf + n, hb_bytes, sizeof hb_bytes);
    n += sizeof hb_bytes;
    memcpy(buf + n, lt_bytes, sizeof lt_bytes);
    buf[n + 30] ^= 0x04;
    n += sizeof lt_bytes;
    {
        static const uint8_t unk[] = {0xFD, 0x01, 0x00, 0x00, 0x00, 0x01, 0x01, 77, 0, 0, 0x42,
                                      0x12, 0x34};
        memcpy(buf + n, unk, sizeof unk);
        n += sizeof unk;
    }
    memcpy(buf + n, dv_bytes, sizeof dv_bytes);
    n += sizeof dv_bytes;
    /* fed in pieces of 7 bytes: MORE until a frame is whole */
    {
        size_t have = 0;
        while (off < n) {
            cdspd_mavlink_result r;
            if (have < n && have - off < 7)
                have = have + 7 > n ? n : have + 7;
            r = cdspd_mavlink_frame_decode(buf + off, have - off, &f, &used);
            if (r == CDSPD_MAVLINK_MORE) {
                assert_true(have < n);
                have = have + 7 > n ? n : have + 7;
                continue;
            }
            assert_true(used > 0);
            off += used;
            if (r == CDSPD_MAVLINK_OK) {
                got_ok++;
                assert_true(f.msgid == 0 || f.msgid == 250);
            }
            junk += r == CDSPD_MAVLINK_JUNK;
            bad += r == CDSPD_MAVLINK_BAD_CRC;
            unknown += r == CDSPD_MAVLINK_UNKNOWN;
        }
    }
    assert_int_equal(got_ok, 2);
    assert_true(bad >= 1);
    assert_int_equal(unknown, 1);
    assert_true(junk >= 1);
    /* a signed frame is 13 bytes longer */
    memcpy(buf, hb_bytes, sizeof hb_bytes);
    buf[2] = CDSPD_MAVLINK_IFLAG_SIGNED;
    assert_int_equal(cdspd_mavlink_frame_decode(buf, sizeof hb_bytes, &f, &used),
                     CDSPD_MAVLINK_MORE);
}

static void test_round_trip_random(void **state)
{
    uint32_t x = 99;
    int t, i;
    (void)state;
    for (t = 0; t < 200; t++) {
        cdspd_mavlink_landing_target m, back;
        cdspd_mavlink_frame f;
        uint8_t pl[CDSPD_MAVLINK_LEN_LANDING_TARGET], out[CDSPD_MAVLINK_MAX_FRAME];
        float *fl[] = {&m.angle_x, &m.angle_y, &m.distance, &m.size_x, &m.size_y, &m.x, &m.y,
                       &m.z, &m.q[0], &m.q[1], &m.q[2], &m.q[3]};
        size_t n, used;
        memset(&m, 0, sizeof m);
        for (i = 0; i < 12; i++) {
            x = x * 1103515245u + 12345u;
            /* some fields zero, so trailing truncation varies */
            *fl[i] = (x >> 28) < 4 ? 0.0f : (float)((int32_t)x) * 1e-6f;
        }
        m.time_usec = (uint64_t)x << 20 | t;
        m.frame = 12;
        m.type = (uint8_t)(t % 4 ? 3 : 0);
        m.position_valid = (uint8_t)(t % 3 ? 1 : 0);
        cdspd_mavlink_pack_landing_target(pl, &m);
        n = cdspd_mavlink_frame_encode(out, sizeof out, (uint8_t)t, 1, 191,
                                       CDSPD_MAVLINK_ID_LANDING_TARGET, pl, sizeof pl);
        assert_true(n >= CDSPD_MAVLINK_HEADER + 3);
        assert_int_equal(cdspd_mavlink_frame_decode(out, n, &f, &used), CDSPD_MAVLINK_OK);
        assert_int_equal(used, n);
        cdspd_mavlink_unpack_landing_target(&f, &back);
        assert_true(back.time_usec == m.time_usec);
        for (i = 0; i < 12; i++) {
            float *b = (float *)((char *)&back + ((char *)fl[i] - (char *)&m));
            assert_memory_equal(b, fl[i], sizeof(float));
        }
        assert_int_equal(back.type, m.type);
        assert_int_equal(back.position_valid, m.position_valid);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_crc),
        cmocka_unit_test(test_crc_extra),
        cmocka_unit_test(test_heartbeat_vector),
        cmocka_unit_test(test_landing_target_vector),
        cmocka_unit_test(test_debug_vect_truncation),
        cmocka_unit_test(test_stream),
        cmocka_unit_test(test_round_trip_random),
    };
    return cmocka_run_group_tests_name("daemon-mavlink", tests, NULL, NULL);
}
