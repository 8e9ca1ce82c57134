/*
 * test_proto.c - cdspd's datagram format (host/proto.c) against
 * docs/protocol.md: byte positions and little-endian order of the binary
 * record, round trips of random records through binary and JSON, the
 * rejection of foreign or damaged datagrams, and the status tokens.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <stdio.h>
#include <math.h>
#include <cmocka.h>

#include "proto.h"

static void random_record(cdsp_rng *g, cdspd_record *r, int ok)
{
    double *d[] = {r->point, r->direction, &r->lines[0][0], &r->segment[0][0], r->sigma_point,
                   r->sigma_direction, r->rms, r->point_body, r->direction_body, r->bound_point,
                   r->bound_direction, r->edge_bound};
    int nd[] = {3, 3, 6, 6, 3, 3, 2, 3, 3, 3, 3, 2}, i, k;
    memset(r, 0, sizeof *r);
    r->version = CDSPD_PROTO_VERSION;
    r->kind = ok ? CDSPD_KIND_FRAME : CDSPD_KIND_STATUS;
    r->seq = cdsp_rng_u32(g);
    r->status = ok ? 0 : CDSPD_ST_SOURCE_DOWN;
    r->flags = ok ? (CDSPD_FLAG_TRACKED | CDSPD_FLAG_RECORDED) : CDSPD_FLAG_SOURCE_DOWN;
    r->frame_id = ((uint64_t)cdsp_rng_u32(g) << 21) ^ cdsp_rng_u32(g);
    r->t_camera_us = ((uint64_t)cdsp_rng_u32(g) << 20) ^ cdsp_rng_u32(g);
    r->t_host_us = ((uint64_t)cdsp_rng_u32(g) << 19) ^ cdsp_rng_u32(g);
    r->radius = 8.25;
    if (ok) {
        for (i = 0; i < 12; i++)
            for (k = 0; k < nd[i]; k++)
                d[i][k] = 1000 * ((double)cdsp_rng_uniform(g) - 0.5) / (1 + k);
        r->bound_distance = 0.5 * (double)cdsp_rng_uniform(g);
        r->distance = 123.456789012345;
        r->alpha = 0.0375;
        r->sigma_distance = 1e-3 * (double)cdsp_rng_uniform(g);
        r->inliers[0] = cdsp_rng_below(g, 5000);
        r->inliers[1] = cdsp_rng_below(g, 5000);
        r->n_edges = cdsp_rng_below(g, 16384);
        r->confidence = (double)cdsp_rng_uniform(g);
    }
    r->proc_us = cdsp_rng_below(g, 100000);
    r->latency_us = cdsp_rng_below(g, 100000);
    r->frames_in = cdsp_rng_u32(g);
    r->frames_dropped = cdsp_rng_u32(g);
    r->frames_bad = cdsp_rng_u32(g);
    r->reconnects = cdsp_rng_below(g, 100);
}

static void assert_records_equal(const cdspd_record *a, const cdspd_record *b)
{
    /* field by field: the struct has padding */
    assert_int_equal(a->kind, b->kind);
    assert_int_equal(a->seq, b->seq);
    assert_int_equal(a->status, b->status);
    assert_int_equal(a->flags, b->flags);
    assert_true(a->frame_id == b->frame_id);
    assert_true(a->t_camera_us == b->t_camera_us);
    assert_true(a->t_host_us == b->t_host_us);
    assert_memory_equal(&a->radius, &b->radius, sizeof a->radius);
    assert_memory_equal(a->point, b->point, sizeof a->point);
    assert_memory_equal(a->direction, b->direction, sizeof a->direction);
    assert_memory_equal(&a->distance, &b->distance, sizeof a->distance);
    assert_memory_equal(&a->alpha, &b->alpha, sizeof a->alpha);
    assert_memory_equal(a->lines, b->lines, sizeof a->lines);
    assert_memory_equal(a->segment, b->segment, sizeof a->segment);
    assert_memory_equal(a->sigma_point, b->sigma_point, sizeof a->sigma_point);
    assert_memory_equal(a->sigma_direction, b->sigma_direction, sizeof a->sigma_direction);
    assert_memory_equal(&a->sigma_distance, &b->sigma_distance, sizeof a->sigma_distance);
    assert_memory_equal(a->rms, b->rms, sizeof a->rms);
    assert_int_equal(a->inliers[0], b->inliers[0]);
    assert_int_equal(a->inliers[1], b->inliers[1]);
    assert_int_equal(a->n_edges, b->n_edges);
    assert_int_equal(a->proc_us, b->proc_us);
    assert_int_equal(a->latency_us, b->latency_us);
    assert_int_equal(a->frames_in, b->frames_in);
    assert_int_equal(a->frames_dropped, b->frames_dropped);
    assert_int_equal(a->frames_bad, b->frames_bad);
    assert_int_equal(a->reconnects, b->reconnects);
    assert_memory_equal(a->point_body, b->point_body, sizeof a->point_body);
    assert_memory_equal(a->direction_body, b->direction_body, sizeof a->direction_body);
    assert_memory_equal(&a->confidence, &b->confidence, sizeof a->confidence);
    assert_memory_equal(a->bound_point, b->bound_point, sizeof a->bound_point);
    assert_memory_equal(a->bound_direction, b->bound_direction, sizeof a->bound_direction);
    assert_memory_equal(&a->bound_distance, &b->bound_distance, sizeof a->bound_distance);
    assert_memory_equal(a->edge_bound, b->edge_bound, sizeof a->edge_bound);
}

/* The byte table of docs/protocol.md, checked with hand-made values. */
static void test_layout(void **state)
{
    cdspd_record r;
    uint8_t b[CDSPD_PROTO_SIZE + 8];
    static const uint8_t one_le[8] = {0, 0, 0, 0, 0, 0, 0xF0, 0x3F};       /* 1.0 */
    static const uint8_t minus2_le[8] = {0, 0, 0, 0, 0, 0, 0x00, 0xC0};    /* -2.0 */
    (void)state;
    memset(&r, 0, sizeof r);
    r.kind = CDSPD_KIND_FRAME;
    r.seq = 0x01020304u;
    r.status = CDSP_E_NO_PIPE; /* -6 */
    r.flags = CDSPD_FLAG_TRACKED | CDSPD_FLAG_RECORDED;
    r.n_edges = 0x0A0B0C0Du;
    r.frame_id = 0x1122334455667788ull;
    r.t_camera_us = 5;
    r.t_host_us = 0x100000000ull;
    r.radius = 1.0;
    r.point[0] = 1.0;
    r.point[2] = -2.0;
    r.direction[1] = 1.0;
    r.distance = -2.0;
    r.segment[1][2] = 1.0;
    r.rms[1] = 1.0;
    r.inliers[1] = 258;
    r.proc_us = 7;
    r.latency_us = 8;
    r.frames_in = 9;
    r.frames_dropped = 10;
    r.frames_bad = 11;
    r.reconnects = 12;
    r.point_body[1] = 1.0;
    r.direction_body[2] = -2.0;
    r.confidence = -2.0;
    r.bound_point[0] = 1.0;
    r.bound_direction[2] = -2.0;
    r.bound_distance = 1.0;
    r.edge_bound[1] = -2.0;
    assert_int_equal(cdspd_proto_encode(&r, b, CDSPD_PROTO_SIZE - 1), 0);
    assert_int_equal(cdspd_proto_encode(&r, b, sizeof b), CDSPD_PROTO_SIZE);
    assert_int_equal(CDSPD_PROTO_SIZE, 452);
    assert_memory_equal(b, "CDSP", 4);
    assert_int_equal(b[4], 4);
    assert_int_equal(b[5], CDSPD_KIND_FRAME);
    assert_int_equal(b[6], 452 & 0xFF);
    assert_int_equal(b[7], 452 >> 8);
    /* version 3: no pipes; version 4: entries of 304 bytes */
    assert_int_equal(b[376], 0);
    assert_int_equal(b[377], 0);
    assert_int_equal(b[378], 304 & 0xFF);
    assert_int_equal(b[379], 304 >> 8);
    /* version 4: the systematic bounds */
    assert_memory_equal(b + 380, one_le, 8);    /* bound_point x */
    assert_memory_equal(b + 420, minus2_le, 8); /* bound_direction z */
    assert_memory_equal(b + 428, one_le, 8);    /* bound_distance */
    assert_memory_equal(b + 444, minus2_le, 8); /* edge_bound[1] */
    assert_memory_equal(b + 368, minus2_le, 8); /* confidence (version 2) */
    assert_int_equal(b[8], 0x04);
    assert_int_equal(b[11], 0x01);
    assert_int_equal(b[12], 0xFA); /* -6, two's complement */
    assert_int_equal(b[13], 0xFF);
    assert_int_equal(b[15], 0xFF);
    assert_int_equal(b[16], 0x11);
    assert_int_equal(b[20], 0x0D);
    assert_int_equal(b[23], 0x0A);
    assert_int_equal(b[24], 0x88);
    assert_int_equal(b[31], 0x11);
    assert_int_equal(b[32], 5);
    assert_int_equal(b[44], 1); /* 2^32 */
    assert_memory_equal(b + 48, one_le, 8);  /* radius */
    assert_memory_equal(b + 56, one_le, 8);  /* point x */
    assert_memory_equal(b + 72, minus2_le, 8); /* point z */
    assert_memory_equal(b + 88, one_le, 8);  /* direction y */
    assert_memory_equal(b + 104, minus2_le, 8); /* distance */
    assert_memory_equal(b + 168 + 40, one_le, 8); /* segment[1][2] */
    assert_memory_equal(b + 280, one_le, 8); /* rms[1] */
    assert_int_equal(b[292], 2);            /* inliers[1] = 258 */
    assert_int_equal(b[293], 1);
    assert_int_equal(b[296], 7);
    assert_int_equal(b[300], 8);
    assert_int_equal(b[304], 9);
    assert_int_equal(b[308], 10);
    assert_int_equal(b[312], 11);
    assert_int_equal(b[316], 12);
    assert_memory_equal(b + 328, one_le, 8);    /* point_body y */
    assert_memory_equal(b + 360, minus2_le, 8); /* direction_body z */
}

static void test_binary_round_trip(void **state)
{
    cdsp_rng g;
    int i;
    (void)state;
    cdsp_rng_seed(&g, 4, 1);
    for (i = 0; i < 200; i++) {
        cdspd_record a, b;
        uint8_t buf[CDSPD_PROTO_SIZE];
        const char *why = NULL;
        random_record(&g, &a, i % 3 != 0);
        assert_int_equal(cdspd_proto_encode(&a, buf, sizeof buf), CDSPD_PROTO_SIZE);
        assert_int_equal(cdspd_proto_decode(buf, sizeof buf, &b, &why), 0);
        assert_int_equal(b.version, 4);
        assert_records_equal(&a, &b);
    }
}

static void test_binary_rejects(void **state)
{
    cdspd_record a, b;
    uint8_t buf[CDSPD_PROTO_SIZE + 80];
    const char *why;
    cdsp_rng g;
    (void)state;
    cdsp_rng_seed(&g, 5, 1);
    random_record(&g, &a, 1);
    cdspd_proto_encode(&a, buf, sizeof buf);
    why = NULL;
    assert_int_equal(cdspd_proto_decode(buf, CDSPD_PROTO_SIZE - 1, &b, &why), -1);
    assert_string_equal(why, "truncated datagram");
    assert_int_equal(cdspd_proto_decode(buf, 3, &b, &why), -1);
    buf[0] = 'X';
    assert_int_equal(cdspd_proto_decode(buf, CDSPD_PROTO_SIZE, &b, &why), -1);
    assert_non_null(strstr(why, "magic"));
    buf[0] = 'C';
    buf[4] = 5;
    assert_int_equal(cdspd_proto_decode(buf, CDSPD_PROTO_SIZE, &b, &why), -1);
    assert_non_null(strstr(why, "version"));
    buf[4] = 4;
    buf[5] = 9;
    assert_int_equal(cdspd_proto_decode(buf, CDSPD_PROTO_SIZE, &b, &why), -1);
    buf[5] = CDSPD_KIND_FRAME;
    buf[6] = (uint8_t)(451 & 0xFF);
    buf[7] = 451 >> 8;
    assert_int_equal(cdspd_proto_decode(buf, CDSPD_PROTO_SIZE, &b, &why), -1);
    /* a longer record of a later revision: fields appended, still read */
    buf[6] = (uint8_t)(520 & 0xFF);
    buf[7] = 520 >> 8;
    memset(buf + CDSPD_PROTO_SIZE, 0x5A, 80);
    assert_int_equal(cdspd_proto_decode(buf, CDSPD_PROTO_SIZE, &b, &why), -1); /* says 520, has 452 */
    assert_int_equal(cdspd_proto_decode(buf, 520, &b, &why), 0);
    assert_records_equal(&a, &b);
    /* a non-finite bound is refused, as every other number */
    memset(buf + 428, 0xFF, 8);
    assert_int_equal(cdspd_proto_decode(buf, 520, &b, &why), -1);
    assert_non_null(strstr(why, "finite"));
    /* a version-3 record (380 bytes) of the previous cdspd: read, bounds zero */
    buf[4] = 3;
    buf[6] = (uint8_t)(380 & 0xFF);
    buf[7] = 380 >> 8;
    assert_int_equal(cdspd_proto_decode(buf, CDSPD_PROTO_SIZE_V3, &b, &why), 0);
    assert_int_equal(b.version, 3);
    assert_true(b.bound_distance == 0 && b.bound_point[0] == 0 && b.edge_bound[1] == 0);
    assert_memory_equal(a.point, b.point, sizeof a.point);
    assert_memory_equal(&a.confidence, &b.confidence, sizeof a.confidence);
    /* a version-2 record (376 bytes) of the previous cdspd: read, no pipes */
    buf[4] = 2;
    buf[6] = (uint8_t)(376 & 0xFF);
    buf[7] = 376 >> 8;
    assert_int_equal(cdspd_proto_decode(buf, CDSPD_PROTO_SIZE_V2, &b, &why), 0);
    assert_int_equal(b.version, 2);
    assert_int_equal(b.n_pipes, 0);
    assert_memory_equal(&a.confidence, &b.confidence, sizeof a.confidence);
    /* a version-1 record (320 bytes) of an older cdspd: read, no body fields */
    buf[4] = 1;
    buf[6] = (uint8_t)(320 & 0xFF);
    buf[7] = 320 >> 8;
    assert_int_equal(cdspd_proto_decode(buf, CDSPD_PROTO_SIZE_V1, &b, &why), 0);
    assert_int_equal(b.version, 1);
    assert_true(b.point_body[0] == 0 && b.direction_body[2] == 0);
    assert_memory_equal(a.point, b.point, sizeof a.point);
    buf[6] = (uint8_t)(319 & 0xFF);
    buf[7] = 319 >> 8;
    assert_int_equal(cdspd_proto_decode(buf, CDSPD_PROTO_SIZE_V1, &b, &why), -1);
}

/* Version 3's pipe list (docs/protocol.md): binary and JSON round trips of
 * records with 0..CDSP_MAX_PIPES pipes, the JSON's pairs, and hostile
 * lists (too many, truncated, a non-finite number, a larger entry of a
 * later revision). */
static void random_pipes(cdsp_rng *g, cdspd_record *r, uint32_t n)
{
    uint32_t k;
    int i;
    r->flags |= CDSPD_FLAG_MULTI;
    r->n_pipes = n;
    for (k = 0; k < n; k++) {
        cdspd_pipe *p = &r->pipe[k];
        double *d[] = {p->point, p->direction, &p->segment[0][0], p->sigma_point,
                       p->sigma_direction, &p->lines[0][0], p->bound_point, p->bound_direction, p->edge_bound};
        int nd[] = {3, 3, 6, 3, 3, 6, 3, 3, 2}, j;
        p->bound_distance = (double)cdsp_rng_uniform(g);
        for (i = 0; i < 9; i++)
            for (j = 0; j < nd[i]; j++)
                d[i][j] = 500 * ((double)cdsp_rng_uniform(g) - 0.5);
        p->distance = 300 + 100 * (double)cdsp_rng_uniform(g);
        p->sigma_distance = 1e-2 * (double)cdsp_rng_uniform(g);
        p->confidence = (double)cdsp_rng_uniform(g);
        p->inliers[0] = cdsp_rng_below(g, 5000);
        p->inliers[1] = cdsp_rng_below(g, 5000);
        p->track_id = 1 + cdsp_rng_below(g, 1000);
    }
}

static void assert_pipes_equal(const cdspd_record *a, const cdspd_record *b)
{
    assert_int_equal(a->n_pipes, b->n_pipes);
    assert_true((a->flags & CDSPD_FLAG_MULTI) == (b->flags & CDSPD_FLAG_MULTI));
    if (a->n_pipes)
        assert_memory_equal(a->pipe, b->pipe, a->n_pipes * sizeof a->pipe[0]);
}

static void test_pipes_round_trip(void **state)
{
    cdsp_rng g;
    uint32_t n;
    (void)state;
    cdsp_rng_seed(&g, 9, 1);
    for (n = 0; n <= CDSP_MAX_PIPES; n++) {
        cdspd_record a, b;
        uint8_t buf[CDSPD_PROTO_MAX_SIZE + 64];
        static char text[65536];
        const char *why = NULL, *p;
        size_t len;
        int pairs = 0;
        random_record(&g, &a, 1);
        memset(a.pipe, 0, sizeof a.pipe);
        random_pipes(&g, &a, n);
        len = cdspd_proto_encode(&a, buf, sizeof buf);
        assert_int_equal(len, CDSPD_PROTO_SIZE + n * CDSPD_PROTO_PIPE_SIZE);
        assert_int_equal(cdspd_proto_encode(&a, buf, len - 1), 0);
        assert_int_equal(cdspd_proto_decode(buf, len, &b, &why), 0);
        assert_records_equal(&a, &b);
        assert_pipes_equal(&a, &b);
        /* JSON: shortest round-trip numbers, so the same bits back */
        assert_true(cdspd_proto_encode_json(&a, text, sizeof text) > 0);
        assert_int_equal(cdspd_proto_decode_json(text, strlen(text), &b, &why), 0);
        assert_pipes_equal(&a, &b);
        for (p = text; (p = strstr(p, "\"axis_distance\":")) != NULL; p++)
            pairs++;
        assert_int_equal(pairs, (int)(n * (n - (n > 0)) / 2));
        if (n == 3) {
            /* hostile: too many pipes, a short list, NaN, and a later revision's larger entries */
            uint8_t big[CDSPD_PROTO_SIZE + 3 * 312];
            uint32_t k;
            buf[376] = CDSP_MAX_PIPES + 1;
            assert_int_equal(cdspd_proto_decode(buf, len, &b, &why), -1);
            assert_non_null(strstr(why, "pipes"));
            buf[376] = 3;
            assert_int_equal(cdspd_proto_decode(buf, len - 1, &b, &why), -1);
            buf[6] = (uint8_t)((len - 8) & 0xFF);
            buf[7] = (uint8_t)((len - 8) >> 8);
            assert_int_equal(cdspd_proto_decode(buf, len, &b, &why), -1);
            assert_string_equal(why, "truncated pipe list");
            buf[6] = (uint8_t)(len & 0xFF);
            buf[7] = (uint8_t)(len >> 8);
            memset(buf + CDSPD_PROTO_SIZE + CDSPD_PROTO_PIPE_SIZE + 48, 0xFF, 8); /* distance: NaN */
            assert_int_equal(cdspd_proto_decode(buf, len, &b, &why), -1);
            memcpy(big, buf, CDSPD_PROTO_SIZE);
            cdspd_proto_encode(&a, buf, sizeof buf);
            for (k = 0; k < 3; k++) {
                memcpy(big + CDSPD_PROTO_SIZE + k * 312, buf + CDSPD_PROTO_SIZE + k * CDSPD_PROTO_PIPE_SIZE,
                       CDSPD_PROTO_PIPE_SIZE);
                memset(big + CDSPD_PROTO_SIZE + k * 312 + CDSPD_PROTO_PIPE_SIZE, 0x5A, 8);
            }
            big[378] = (uint8_t)(312 & 0xFF);
            big[379] = (uint8_t)(312 >> 8);
            big[6] = (uint8_t)(sizeof big & 0xFF);
            big[7] = (uint8_t)(sizeof big >> 8);
            assert_int_equal(cdspd_proto_decode(big, sizeof big, &b, &why), 0);
            assert_pipes_equal(&a, &b);
            /* version 3 of the same pipes (entries of 232 bytes after 380):
             * read, the bounds zero; a version-4 entry size below 304 is
             * refused */
            {
                uint8_t v3[CDSPD_PROTO_SIZE_V3 + 3 * CDSPD_PROTO_PIPE_SIZE_V3];
                memcpy(v3, buf, CDSPD_PROTO_SIZE_V3);
                for (k = 0; k < 3; k++)
                    memcpy(v3 + CDSPD_PROTO_SIZE_V3 + k * CDSPD_PROTO_PIPE_SIZE_V3,
                           buf + CDSPD_PROTO_SIZE + k * CDSPD_PROTO_PIPE_SIZE, CDSPD_PROTO_PIPE_SIZE_V3);
                v3[4] = 3;
                v3[6] = (uint8_t)(sizeof v3 & 0xFF);
                v3[7] = (uint8_t)(sizeof v3 >> 8);
                v3[378] = CDSPD_PROTO_PIPE_SIZE_V3;
                v3[379] = 0;
                assert_int_equal(cdspd_proto_decode(v3, sizeof v3, &b, &why), 0);
                assert_int_equal(b.n_pipes, 3);
                for (k = 0; k < 3; k++) {
                    assert_memory_equal(a.pipe[k].point, b.pipe[k].point, sizeof a.pipe[k].point);
                    assert_int_equal(a.pipe[k].track_id, b.pipe[k].track_id);
                    assert_true(b.pipe[k].bound_distance == 0 && b.pipe[k].edge_bound[0] == 0);
                }
                buf[378] = CDSPD_PROTO_PIPE_SIZE_V3;
                buf[379] = 0;
                assert_int_equal(cdspd_proto_decode(buf, len, &b, &why), -1);
            }
        }
    }
}

static void test_json_round_trip(void **state)
{
    cdsp_rng g;
    int i;
    char text[4096];
    (void)state;
    cdsp_rng_seed(&g, 6, 1);
    for (i = 0; i < 100; i++) {
        cdspd_record a, b;
        size_t n;
        const char *why = NULL;
        random_record(&g, &a, i % 4 != 0);
        /* JSON carries tracked/full-search as one boolean */
        if (a.status == 0)
            a.flags &= ~CDSPD_FLAG_FULL_SEARCH;
        n = cdspd_proto_encode_json(&a, text, sizeof text);
        assert_true(n > 0 && n == strlen(text));
        if (cdspd_proto_decode_json(text, n, &b, &why))
            fail_msg("%s: %s", why, text);
        assert_records_equal(&a, &b);
    }
}

static void test_json_fields(void **state)
{
    cdspd_record a;
    char text[4096];
    cdsp_rng g;
    static const char *const names[] = {"\"seq\":", "\"t_camera_us\":", "\"t_host_us\":",
                                        "\"status\":\"ok\"", "\"point\":[", "\"direction\":[",
                                        "\"distance\":", "\"segment\":[[", "\"sigma\":{",
                                        "\"inliers\":[", "\"radius\":", "\"tracked\":true",
                                        "\"frames_dropped\":", "\"latency_us\":"};
    size_t i;
    (void)state;
    cdsp_rng_seed(&g, 7, 1);
    random_record(&g, &a, 1);
    assert_true(cdspd_proto_encode_json(&a, text, sizeof text) > 0);
    for (i = 0; i < sizeof names / sizeof names[0]; i++)
        if (!strstr(text, names[i]))
            fail_msg("no %s in %s", names[i], text);
    random_record(&g, &a, 0);
    assert_true(cdspd_proto_encode_json(&a, text, sizeof text) > 0);
    assert_non_null(strstr(text, "\"status\":\"error\",\"error\":\"source-down\""));
    assert_non_null(strstr(text, "\"kind\":\"status\""));
    assert_null(strstr(text, "\"point\""));
    /* too small a buffer: nothing, not a truncated object */
    assert_int_equal(cdspd_proto_encode_json(&a, text, 40), 0);
    /* the decoder refuses what is not a record */
    {
        cdspd_record b;
        const char *why;
        assert_int_equal(cdspd_proto_decode_json("{\"seq\": 1}", 10, &b, &why), -1);
        assert_int_equal(cdspd_proto_decode_json("[1,2]", 5, &b, &why), -1);
        assert_int_equal(cdspd_proto_decode_json("{\"seq\":", 7, &b, &why), -1);
    }
}

/* Issue 16: hostile JSON datagrams are refused, never crash or reach an
 * undefined conversion: null kind/status/error (strcmp of NULL killed the
 * receiver), counts out of range, non-finite numbers, bytes after the
 * object (a second, fake record smuggled behind the first). Each is a
 * valid record with one field replaced. The corpus files
 * tests/fuzz/corpus/listen/regress-* (the fuzz target's seeds) are refused
 * too. */
static void test_json_hostile(void **state)
{
    static const struct {
        const char *field, *value;
    } bad[] = {
        {"\"kind\":", "null"},          {"\"kind\":", "7"},           {"\"kind\":", "\"bogus\""},
        {"\"status\":", "null"},        {"\"status\":", "[]"},        {"\"inliers\":", "[1e300,2]"},
        {"\"inliers\":", "[-1,2]"},     {"\"inliers\":", "[4294967296,2]"},
        {"\"inliers\":", "[1.5,2]"},    {"\"inliers\":", "[NaN,2]"},  {"\"edges\":", "-1"},
        {"\"edges\":", "1e300"},        {"\"edges\":", "Infinity"},   {"\"edges\":", "null"},
        {"\"point\":", "[NaN,0,0]"},    {"\"distance\":", "-Infinity"},
    };
    static const char *const files[] = {"regress-kind-null.json", "regress-status-null.json",
                                        "regress-error-null.json",
                                        "regress-trailing-injection.json",
                                        "regress-binary-nan-radius.bin",
                                        "regress-binary-unknown-status.bin",
                                        "regress-binary-status-ok.bin"};
    cdspd_record a, b;
    char text[4096], mut[8400];
    cdsp_rng g;
    const char *why;
    size_t i, n;
    (void)state;
    cdsp_rng_seed(&g, 8, 1);
    random_record(&g, &a, 1);
    a.kind = CDSPD_KIND_FRAME;
    n = cdspd_proto_encode_json(&a, text, sizeof text);
    assert_true(n > 0);
    assert_int_equal(cdspd_proto_decode_json(text, n, &b, &why), 0);
    for (i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        const char *at = strstr(text, bad[i].field), *end;
        assert_non_null(at);
        at += strlen(bad[i].field);
        /* the old value ends at the first ',' or '}' outside brackets */
        end = at;
        if (*end == '[') {
            end = strchr(end, ']') + 1;
        } else {
            while (*end != ',' && *end != '}')
                end++;
        }
        snprintf(mut, sizeof mut, "%.*s%s%s", (int)(at - text), text, bad[i].value, end);
        if (cdspd_proto_decode_json(mut, strlen(mut), &b, &why) != -1)
            fail_msg("accepted %s%s", bad[i].field, bad[i].value);
    }
    /* an error record whose error is null, or not a known token */
    random_record(&g, &a, 0);
    a.kind = CDSPD_KIND_FRAME;
    a.status = CDSP_E_NO_PIPE;
    n = cdspd_proto_encode_json(&a, text, sizeof text);
    assert_int_equal(cdspd_proto_decode_json(text, n, &b, &why), 0);
    {
        char *e = strstr(text, "\"error\":\"no-pipe\"");
        assert_non_null(e);
        snprintf(mut, sizeof mut, "%.*s\"error\":null%s", (int)(e - text), text, e + 17);
        assert_int_equal(cdspd_proto_decode_json(mut, strlen(mut), &b, &why), -1);
        snprintf(mut, sizeof mut, "%.*s\"error\":\"ok\"%s", (int)(e - text), text, e + 17);
        assert_int_equal(cdspd_proto_decode_json(mut, strlen(mut), &b, &why), -1);
    }
    /* white space after the object is fine, anything else is not */
    snprintf(mut, sizeof mut, "%s \r\n", text);
    assert_int_equal(cdspd_proto_decode_json(mut, strlen(mut), &b, &why), 0);
    snprintf(mut, sizeof mut, "%s\n%s", text, text);
    assert_int_equal(cdspd_proto_decode_json(mut, strlen(mut), &b, &why), -1);
    assert_string_equal(why, "bytes after the JSON object");
    /* found by tests/fuzz listen (corpus/listen/regress-binary-nan-radius.bin):
     * a binary record's NaN became JSON null, which no decoder takes back;
     * both decoders now refuse non-finite numbers, radius included */
    {
        uint8_t bin[CDSPD_PROTO_SIZE];
        double nan_v = NAN;
        random_record(&g, &a, 1);
        a.kind = CDSPD_KIND_FRAME;
        assert_int_equal(cdspd_proto_encode(&a, bin, sizeof bin), CDSPD_PROTO_SIZE);
        assert_int_equal(cdspd_proto_decode(bin, sizeof bin, &b, &why), 0);
        memcpy(bin + 48, &nan_v, 8); /* OFF_RADIUS, docs/protocol.md */
        assert_int_equal(cdspd_proto_decode(bin, sizeof bin, &b, &why), -1);
        assert_string_equal(why, "a number in the record is not finite");
        /* likewise a status without a token (regress-binary-unknown-status.bin) */
        assert_int_equal(cdspd_proto_encode(&a, bin, sizeof bin), CDSPD_PROTO_SIZE);
        bin[12] = 0x00;
        bin[13] = 0x00;
        bin[14] = 0x01; /* OFF_STATUS: 65536 */
        bin[15] = 0x00;
        assert_int_equal(cdspd_proto_decode(bin, sizeof bin, &b, &why), -1);
        assert_string_equal(why, "unknown status");
        /* and a status record with status 0 (regress-binary-status-ok.bin) */
        a.kind = CDSPD_KIND_STATUS;
        a.status = 0;
        assert_int_equal(cdspd_proto_encode(&a, bin, sizeof bin), CDSPD_PROTO_SIZE);
        assert_int_equal(cdspd_proto_decode(bin, sizeof bin, &b, &why), -1);
        assert_string_equal(why, "a status record without a status");
        n = cdspd_proto_encode_json(&a, text, sizeof text);
        {
            char *rad = strstr(text, "\"radius\":");
            assert_non_null(rad);
            snprintf(mut, sizeof mut, "%.*s\"radius\":null%s", (int)(rad - text), text,
                     strchr(rad, ','));
            assert_int_equal(cdspd_proto_decode_json(mut, strlen(mut), &b, &why), -1);
        }
    }
    for (i = 0; i < sizeof files / sizeof files[0]; i++) {
        char path[256];
        FILE *f;
        snprintf(path, sizeof path, "tests/fuzz/corpus/listen/%s", files[i]);
        f = fopen(path, "rb");
        if (!f)
            fail_msg("%s: cannot open (run from the repository's top)", path);
        n = fread(mut, 1, sizeof mut, f);
        fclose(f);
        if (cdspd_proto_decode_any((const uint8_t *)mut, n, &b, NULL, &why) != -1)
            fail_msg("%s: accepted", path);
    }
}

static void test_status_tokens(void **state)
{
    int s, back;
    (void)state;
    for (s = 0; s >= CDSP_E_FORMAT; s--) {
        assert_string_equal(cdspd_status_token(s), cdsp_status_token((cdsp_status)s));
        assert_true(cdspd_status_from_token(cdspd_status_token(s), &back));
        assert_int_equal(back, s);
    }
    assert_string_equal(cdspd_status_token(CDSPD_ST_NO_FRAME), "no-frame");
    assert_string_equal(cdspd_status_token(CDSPD_ST_SOURCE_DOWN), "source-down");
    assert_string_equal(cdspd_status_token(CDSPD_ST_BAD_FRAME), "bad-frame");
    assert_true(cdspd_status_from_token("bad-frame", &back));
    assert_int_equal(back, CDSPD_ST_BAD_FRAME);
    assert_string_equal(cdspd_status_token(-50), "unknown");
    assert_false(cdspd_status_from_token("nonsense", &back));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_layout),         cmocka_unit_test(test_binary_round_trip),
        cmocka_unit_test(test_binary_rejects), cmocka_unit_test(test_json_round_trip),
        cmocka_unit_test(test_json_fields),    cmocka_unit_test(test_status_tokens),
        cmocka_unit_test(test_json_hostile),   cmocka_unit_test(test_pipes_round_trip),
    };
    return cmocka_run_group_tests_name("daemon-proto", tests, NULL, NULL);
}
