/*
 * test_pool.c - the frame pool (daemon/pool.c): latest frame wins, every
 * replaced frame is counted as dropped, a take times out when nothing
 * comes, and under two threads frames arrive in order, each at most once,
 * with taken + dropped = published. A lossless pool (a replay) hands over
 * every frame in order and never drops, and a wake releases a publisher
 * waiting for the taker.
 */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <stdio.h>
#include <pthread.h>
#include <time.h>
#include <cmocka.h>

#include "pool.h"

static void publish_id(cdspd_pool *p, uint64_t id)
{
    cdspd_frame *f = cdspd_pool_back(p);
    f->frame_id = id;
    f->data[0] = (uint8_t)id;
    cdspd_pool_publish(p);
}

static void test_latest_wins(void **state)
{
    cdspd_pool p;
    cdspd_frame *f;
    uint64_t t0;
    (void)state;
    assert_int_equal(cdspd_pool_init(&p, 64), 0);
    /* nothing yet: a take times out (after about its timeout) */
    t0 = cdspd_now_us();
    assert_null(cdspd_pool_take(&p, 20000));
    assert_true(cdspd_now_us() - t0 >= 19000);
    publish_id(&p, 1);
    publish_id(&p, 2);
    publish_id(&p, 3);
    assert_int_equal(cdspd_pool_dropped(&p), 2);
    f = cdspd_pool_take(&p, 0);
    assert_non_null(f);
    assert_int_equal(f->frame_id, 3);
    assert_int_equal(f->data[0], 3);
    assert_true(f->t_ready_us > 0);
    /* the frame held by the taker is not overwritten by later publishes */
    publish_id(&p, 4);
    publish_id(&p, 5);
    assert_int_equal(f->frame_id, 3);
    assert_int_equal(cdspd_pool_take(&p, 0)->frame_id, 5);
    assert_null(cdspd_pool_take(&p, 0));
    assert_int_equal(cdspd_pool_dropped(&p), 3);
    /* after a wake (stop) takes return at once */
    publish_id(&p, 6);
    cdspd_pool_wake(&p);
    assert_null(cdspd_pool_take(&p, 1000000));
    cdspd_pool_destroy(&p);
}

#define N_FRAMES 20000

static void *producer(void *arg)
{
    cdspd_pool *p = arg;
    uint64_t i;
    for (i = 1; i <= N_FRAMES; i++) {
        cdspd_frame *f = cdspd_pool_back(p);
        f->frame_id = i;
        memset(f->data, (int)(i & 0xFF), f->cap);
        cdspd_pool_publish(p);
    }
    return NULL;
}

static void test_two_threads(void **state)
{
    cdspd_pool p;
    pthread_t th;
    uint64_t last = 0, taken = 0;
    (void)state;
    assert_int_equal(cdspd_pool_init(&p, 4096), 0);
    assert_int_equal(pthread_create(&th, NULL, producer, &p), 0);
    while (last < N_FRAMES) {
        cdspd_frame *f = cdspd_pool_take(&p, 2000000);
        size_t k;
        assert_non_null(f);
        if (f->frame_id <= last)
            fail_msg("frame %llu after %llu", (unsigned long long)f->frame_id, (unsigned long long)last);
        /* the whole buffer is the frame it says (never written while held) */
        for (k = 0; k < f->cap; k++)
            if (f->data[k] != (uint8_t)(f->frame_id & 0xFF))
                fail_msg("frame %llu torn at byte %zu", (unsigned long long)f->frame_id, k);
        last = f->frame_id;
        taken++;
    }
    pthread_join(th, NULL);
    assert_int_equal(taken + cdspd_pool_dropped(&p), N_FRAMES);
    cdspd_pool_destroy(&p);
}

static void test_lossless_two_threads(void **state)
{
    cdspd_pool p;
    pthread_t th;
    uint64_t want = 1;
    (void)state;
    assert_int_equal(cdspd_pool_init(&p, 4096), 0);
    cdspd_pool_set_lossless(&p, 1);
    assert_int_equal(pthread_create(&th, NULL, producer, &p), 0);
    while (want <= N_FRAMES) {
        cdspd_frame *f = cdspd_pool_take(&p, 2000000);
        size_t k;
        assert_non_null(f);
        if (f->frame_id != want)
            fail_msg("frame %llu where %llu was due", (unsigned long long)f->frame_id,
                     (unsigned long long)want);
        for (k = 0; k < f->cap; k++)
            if (f->data[k] != (uint8_t)(f->frame_id & 0xFF))
                fail_msg("frame %llu torn at byte %zu", (unsigned long long)f->frame_id, k);
        want++;
    }
    pthread_join(th, NULL);
    assert_int_equal(cdspd_pool_dropped(&p), 0);
    assert_null(cdspd_pool_take(&p, 0));
    cdspd_pool_destroy(&p);
}

static void *publish_two(void *arg)
{
    cdspd_pool *p = arg;
    publish_id(p, 1);
    publish_id(p, 2); /* waits: frame 1 is not taken */
    return NULL;
}

static void test_lossless_wake(void **state)
{
    cdspd_pool p;
    pthread_t th;
    (void)state;
    assert_int_equal(cdspd_pool_init(&p, 64), 0);
    cdspd_pool_set_lossless(&p, 1);
    assert_int_equal(pthread_create(&th, NULL, publish_two, &p), 0);
    /* whatever the scheduling, the publisher cannot finish before a wake or
     * a take: the join below returns only because of the wake */
    cdspd_pool_wake(&p);
    pthread_join(th, NULL);
    assert_int_equal(cdspd_pool_dropped(&p), 0);
    cdspd_pool_destroy(&p);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_latest_wins),
        cmocka_unit_test(test_two_threads),
        cmocka_unit_test(test_lossless_two_threads),
        cmocka_unit_test(test_lossless_wake),
    };
    return cmocka_run_group_tests_name("daemon-pool", tests, NULL, NULL);
}
