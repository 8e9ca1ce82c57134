/*
 * test_host_addr.c - host/addr.c, the one parser of cdspd's destinations,
 * the MAVLink udpout host, `cdsp_tool listen ADDR:PORT` and the test
 * receivers' --bind: the forms accepted (family and port of what they
 * resolve to) and the errors, each with the words its message must hold.
 * Numeric addresses only (no name service needed).
 */
#define _POSIX_C_SOURCE 200809L
#include "tool_test.h"

#include <arpa/inet.h>
#include <netinet/in.h>

#include "addr.h"

static unsigned port_of(const struct sockaddr_storage *ss)
{
    return ss->ss_family == AF_INET6 ? ntohs(((const struct sockaddr_in6 *)ss)->sin6_port)
                                     : ntohs(((const struct sockaddr_in *)ss)->sin_port);
}

static void accepted_forms(void **state)
{
    static const struct {
        const char *text;
        int passive, family;
        unsigned port;
    } ok[] = {
        {"127.0.0.1", 0, AF_INET, CDSP_HOST_DEFAULT_PORT},
        {"127.0.0.1:7", 0, AF_INET, 7},
        {"239.1.2.3:7", 0, AF_INET, 7},
        {"[::1]:7", 0, AF_INET6, 7},
        {"[::1]", 0, AF_INET6, CDSP_HOST_DEFAULT_PORT},
        {":7", 1, AF_INET, 7},          /* listen's any address: IPv4 */
        {"0.0.0.0", 1, AF_INET, CDSP_HOST_DEFAULT_PORT},
        {"0.0.0.0:0", 1, AF_INET, 0},   /* a passive port 0: the kernel picks */
        {"[::]:9", 1, AF_INET6, 9},
        {"127.0.0.1:010", 0, AF_INET, 10}, /* decimal, never octal */
    };
    size_t i;
    (void)state;
    for (i = 0; i < sizeof ok / sizeof ok[0]; i++) {
        struct sockaddr_storage ss;
        socklen_t len = 0;
        cdsp_host_err err = {{0}};
        if (cdsp_host_addr_parse(ok[i].text, ok[i].passive, &ss, &len, &err) != CDSP_HOST_OK)
            fail_msg("'%s' refused: %s", ok[i].text, err.msg);
        assert_int_equal(ss.ss_family, ok[i].family);
        assert_int_equal(port_of(&ss), ok[i].port);
        assert_true(len > 0);
    }
}

static void refused_forms(void **state)
{
    static const struct {
        const char *text;
        int passive;
        const char *words;
    } bad[] = {
        {":7", 0, "no host"},
        {"[::1", 0, "expected [IPV6]:PORT"},
        {"[]:7", 1, "expected [IPV6]:PORT"},
        {"[::1]x", 0, "expected [IPV6]:PORT"},
        {"fe80::1:9", 0, "write IPv6 addresses as [ADDR]:PORT"},
        {"1.2.3.4:x", 0, "port 'x': expected 1..65535"},
        {"1.2.3.4:0", 0, "port '0': expected 1..65535"},
        {"1.2.3.4:65536", 1, "port '65536': expected 0..65535"},
        {"1.2.3.4:", 0, "port '': expected 1..65535"},
    };
    size_t i;
    (void)state;
    for (i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        struct sockaddr_storage ss;
        socklen_t len;
        cdsp_host_err err = {{0}};
        assert_int_equal(cdsp_host_addr_parse(bad[i].text, bad[i].passive, &ss, &len, &err),
                         CDSP_HOST_E_FORMAT);
        tt_assert_contains(err.msg, bad[i].words);
        /* the message names the text as given */
        tt_assert_contains(err.msg, bad[i].text);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(accepted_forms),
        cmocka_unit_test(refused_forms),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
