/*
 * fuzz_mavlink.c - the MAVLink side of cdspd (daemon/mavlink.c, mount.c,
 * mavout.c's URL parser): what the encoder is fed (a mount of any angles and
 * offset, a pose with NaN, Inf, huge or tiny numbers, message fields of any
 * value, any sequence/system/component ids), checked by decoding what it
 * wrote: the frame decodes with its own CRC and unpacks to the same bytes;
 * and the stream decoder fed the rest of the input as received bytes (a
 * receiver's loop: every result consumes at least one byte, none reads
 * past the buffer). The mavlink key's URL text is parsed without lookups.
 */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_input.h"
#include "mavlink.h"
#include "mavout.h"
#include "mount.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void round_trip(uint32_t msgid, const uint8_t *payload, size_t len, uint8_t seq,
                       uint8_t sysid, uint8_t compid)
{
    uint8_t frame[CDSPD_MAVLINK_MAX_FRAME];
    cdspd_mavlink_frame f;
    size_t n = cdspd_mavlink_frame_encode(frame, sizeof frame, seq, sysid, compid, msgid, payload,
                                          len), used = 0;
    if (n == 0)
        abort(); /* a known message that fits must encode */
    if (cdspd_mavlink_frame_decode(frame, n, &f, &used) != CDSPD_MAVLINK_OK || used != n ||
        f.msgid != msgid || f.seq != seq || f.sysid != sysid || f.compid != compid ||
        memcmp(f.payload, payload, len) != 0)
        abort(); /* what was written must read back */
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fz_in in = {data, size};
    cdspd_mount mount;
    cdspd_body_pose body;
    cdspd_mavlink_landing_target lt, lt2;
    cdspd_mavlink_debug_vect dv, dv2;
    cdspd_mavlink_heartbeat hb, hb2;
    cdspd_mavlink_frame f;
    uint8_t payload[CDSPD_MAVLINK_MAX_PAYLOAD];
    double rpy[3], t[3], p[3], v[3];
    uint8_t seq = fz_u8(&in), sysid = fz_u8(&in), compid = fz_u8(&in);
    size_t len, pos, used;
    int k;

    for (k = 0; k < 3; k++) {
        rpy[k] = fz_real(&in, -180, 180);
        t[k] = fz_real(&in, -1000, 1000);
        p[k] = fz_real(&in, -5000, 5000);
        v[k] = fz_real(&in, -1, 1);
    }
    if (v[0] == 0 && v[1] == 0 && v[2] == 0)
        v[2] = 1; /* the contract: not zero */
    cdspd_mount_from_euler(&mount, rpy, t);
    cdspd_mount_apply(&mount, p, v, &body);

    /* LANDING_TARGET with the body pose's numbers, as mavout fills it */
    memset(&lt, 0, sizeof lt);
    lt.time_usec = (uint64_t)fz_u32(&in) << 20;
    lt.angle_x = (float)body.yaw;
    lt.angle_y = (float)body.pitch;
    lt.distance = (float)fz_real(&in, 0, 100);
    lt.x = (float)body.point[0];
    lt.y = (float)body.point[1];
    lt.z = (float)body.point[2];
    for (k = 0; k < 4; k++)
        lt.q[k] = (float)body.q[k];
    lt.frame = fz_u8(&in);
    lt.type = fz_u8(&in);
    lt.position_valid = fz_u8(&in);
    len = cdspd_mavlink_pack_landing_target(payload, &lt);
    if (len != CDSPD_MAVLINK_LEN_LANDING_TARGET)
        abort();
    round_trip(CDSPD_MAVLINK_ID_LANDING_TARGET, payload, len, seq, sysid, compid);
    memset(&f, 0, sizeof f);
    f.msgid = CDSPD_MAVLINK_ID_LANDING_TARGET;
    f.len = (uint8_t)len;
    memcpy(f.payload, payload, len);
    if (cdspd_mavlink_unpack_landing_target(&f, &lt2) == 0 &&
        memcmp(&lt2.x, &lt.x, sizeof lt.x) != 0)
        abort();

    memset(&dv, 0, sizeof dv);
    dv.x = (float)body.direction[0];
    dv.y = (float)body.direction[1];
    dv.z = (float)body.direction[2];
    for (k = 0; k < 10; k++)
        dv.name[k] = (char)fz_u8(&in);
    len = cdspd_mavlink_pack_debug_vect(payload, &dv);
    round_trip(CDSPD_MAVLINK_ID_DEBUG_VECT, payload, len, seq, sysid, compid);
    memcpy(f.payload, payload, len);
    f.msgid = CDSPD_MAVLINK_ID_DEBUG_VECT;
    f.len = (uint8_t)len;
    if (cdspd_mavlink_unpack_debug_vect(&f, &dv2) == 0 && memcmp(dv2.name, dv.name, 10) != 0)
        abort();

    memset(&hb, 0, sizeof hb);
    hb.custom_mode = fz_u32(&in);
    hb.type = fz_u8(&in);
    hb.system_status = fz_u8(&in);
    len = cdspd_mavlink_pack_heartbeat(payload, &hb);
    round_trip(CDSPD_MAVLINK_ID_HEARTBEAT, payload, len, seq, sysid, compid);
    memcpy(f.payload, payload, len);
    f.msgid = CDSPD_MAVLINK_ID_HEARTBEAT;
    f.len = (uint8_t)len;
    (void)cdspd_mavlink_unpack_heartbeat(&f, &hb2);

    /* a URL of the mavlink key, from a length byte and the next bytes */
    {
        char url[300];
        char err[512];
        cdspd_mavlink_url u;
        size_t ul = fz_u8(&in);
        ul = ul < in.n ? ul : in.n;
        memcpy(url, in.p, ul);
        url[ul] = 0;
        in.p += ul;
        in.n -= ul;
        if (strlen(url) == ul)
            (void)cdspd_mavlink_url_parse(url, &u, 0, err, sizeof err);
    }

    /* the rest: a received byte stream, decoded as a receiver does */
    for (pos = 0; pos < in.n; pos += used) {
        cdspd_mavlink_result r = cdspd_mavlink_frame_decode(in.p + pos, in.n - pos, &f, &used);
        if (r == CDSPD_MAVLINK_MORE)
            break;
        if (used == 0 || used > in.n - pos)
            abort(); /* a decoder that does not advance, or claims bytes it was not given */
    }
    return 0;
}
