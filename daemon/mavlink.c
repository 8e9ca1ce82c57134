/*
 * mavlink.c - see mavlink.h. Bytes are written one by one (shifts), so the
 * encoding is little endian whatever the host's order; a float is its IEEE
 * 754 binary32 bits moved through a uint32_t.
 */
#include "mavlink.h"

#include <string.h>

uint16_t cdspd_mavlink_crc(uint16_t crc, const uint8_t *p, size_t n)
{
    /* The MAVLink reference's byte-wise form of CRC-16/MCRF4XX (X.25
     * polynomial x^16 + x^12 + x^5 + 1, reflected 0x8408): equal to
     * shifting the byte's eight bits through the register one at a time. */
    size_t i;
    for (i = 0; i < n; i++) {
        uint8_t t = (uint8_t)(p[i] ^ (uint8_t)(crc & 0xFF));
        t = (uint8_t)(t ^ (uint8_t)(t << 4));
        crc = (uint16_t)((crc >> 8) ^ ((uint16_t)t << 8) ^ ((uint16_t)t << 3) ^ ((uint16_t)t >> 4));
    }
    return crc;
}

int cdspd_mavlink_crc_extra(uint32_t msgid)
{
    /* common.xml's CRC_EXTRA values (docs/mavlink.md) */
    switch (msgid) {
    case CDSPD_MAVLINK_ID_HEARTBEAT: return 50;
    case CDSPD_MAVLINK_ID_LANDING_TARGET: return 200;
    case CDSPD_MAVLINK_ID_DEBUG_VECT: return 49;
    case CDSPD_MAVLINK_ID_NAMED_VALUE_FLOAT: return 170;
    default: return -1;
    }
}

/* ------------------------------------------------------------------------
 * Little-endian fields.
 * ---------------------------------------------------------------------- */
static uint8_t *put_u32(uint8_t *p, uint32_t v)
{
    int i;
    for (i = 0; i < 4; i++)
        p[i] = (uint8_t)(v >> (8 * i));
    return p + 4;
}

static uint8_t *put_u64(uint8_t *p, uint64_t v)
{
    int i;
    for (i = 0; i < 8; i++)
        p[i] = (uint8_t)(v >> (8 * i));
    return p + 8;
}

static uint8_t *put_f32(uint8_t *p, float v)
{
    uint32_t u;
    memcpy(&u, &v, sizeof u);
    return put_u32(p, u);
}

static const uint8_t *get_u32(const uint8_t *p, uint32_t *v)
{
    *v = (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
    return p + 4;
}

static const uint8_t *get_u64(const uint8_t *p, uint64_t *v)
{
    uint32_t lo, hi;
    get_u32(p, &lo);
    get_u32(p + 4, &hi);
    *v = (uint64_t)hi << 32 | lo;
    return p + 8;
}

static const uint8_t *get_f32(const uint8_t *p, float *v)
{
    uint32_t u;
    p = get_u32(p, &u);
    memcpy(v, &u, sizeof *v);
    return p;
}

/* ------------------------------------------------------------------------
 * Messages, in wire order.
 * ---------------------------------------------------------------------- */
size_t cdspd_mavlink_pack_heartbeat(uint8_t *p, const cdspd_mavlink_heartbeat *m)
{
    uint8_t *q = put_u32(p, m->custom_mode);
    *q++ = m->type;
    *q++ = m->autopilot;
    *q++ = m->base_mode;
    *q++ = m->system_status;
    *q++ = m->mavlink_version;
    return (size_t)(q - p);
}

size_t cdspd_mavlink_pack_landing_target(uint8_t *p, const cdspd_mavlink_landing_target *m)
{
    uint8_t *q = put_u64(p, m->time_usec);
    int i;
    q = put_f32(q, m->angle_x);
    q = put_f32(q, m->angle_y);
    q = put_f32(q, m->distance);
    q = put_f32(q, m->size_x);
    q = put_f32(q, m->size_y);
    *q++ = m->target_num;
    *q++ = m->frame;
    q = put_f32(q, m->x);
    q = put_f32(q, m->y);
    q = put_f32(q, m->z);
    for (i = 0; i < 4; i++)
        q = put_f32(q, m->q[i]);
    *q++ = m->type;
    *q++ = m->position_valid;
    return (size_t)(q - p);
}

size_t cdspd_mavlink_pack_debug_vect(uint8_t *p, const cdspd_mavlink_debug_vect *m)
{
    uint8_t *q = put_u64(p, m->time_usec);
    q = put_f32(q, m->x);
    q = put_f32(q, m->y);
    q = put_f32(q, m->z);
    memcpy(q, m->name, sizeof m->name);
    return (size_t)(q + sizeof m->name - p);
}

int cdspd_mavlink_unpack_heartbeat(const cdspd_mavlink_frame *f, cdspd_mavlink_heartbeat *m)
{
    const uint8_t *q = f->payload;
    if (f->msgid != CDSPD_MAVLINK_ID_HEARTBEAT)
        return -1;
    q = get_u32(q, &m->custom_mode);
    m->type = q[0];
    m->autopilot = q[1];
    m->base_mode = q[2];
    m->system_status = q[3];
    m->mavlink_version = q[4];
    return 0;
}

int cdspd_mavlink_unpack_landing_target(const cdspd_mavlink_frame *f,
                                        cdspd_mavlink_landing_target *m)
{
    const uint8_t *q = f->payload;
    int i;
    if (f->msgid != CDSPD_MAVLINK_ID_LANDING_TARGET)
        return -1;
    q = get_u64(q, &m->time_usec);
    q = get_f32(q, &m->angle_x);
    q = get_f32(q, &m->angle_y);
    q = get_f32(q, &m->distance);
    q = get_f32(q, &m->size_x);
    q = get_f32(q, &m->size_y);
    m->target_num = *q++;
    m->frame = *q++;
    q = get_f32(q, &m->x);
    q = get_f32(q, &m->y);
    q = get_f32(q, &m->z);
    for (i = 0; i < 4; i++)
        q = get_f32(q, &m->q[i]);
    m->type = q[0];
    m->position_valid = q[1];
    return 0;
}

int cdspd_mavlink_unpack_debug_vect(const cdspd_mavlink_frame *f, cdspd_mavlink_debug_vect *m)
{
    const uint8_t *q = f->payload;
    if (f->msgid != CDSPD_MAVLINK_ID_DEBUG_VECT)
        return -1;
    q = get_u64(q, &m->time_usec);
    q = get_f32(q, &m->x);
    q = get_f32(q, &m->y);
    q = get_f32(q, &m->z);
    memcpy(m->name, q, sizeof m->name);
    return 0;
}

/* ------------------------------------------------------------------------
 * Framing.
 * ---------------------------------------------------------------------- */
size_t cdspd_mavlink_frame_encode(uint8_t *out, size_t cap, uint8_t seq, uint8_t sysid,
                                  uint8_t compid, uint32_t msgid, const uint8_t *payload,
                                  size_t len)
{
    int extra = cdspd_mavlink_crc_extra(msgid);
    uint16_t crc;
    uint8_t x;
    if (extra < 0 || len > CDSPD_MAVLINK_MAX_PAYLOAD || msgid > 0xFFFFFFu)
        return 0;
    /* trailing zeros are not sent; at least one payload byte is */
    while (len > 1 && payload[len - 1] == 0)
        len--;
    if (cap < CDSPD_MAVLINK_HEADER + len + 2)
        return 0;
    out[0] = CDSPD_MAVLINK_STX;
    out[1] = (uint8_t)len;
    out[2] = 0; /* incompat_flags: not signed */
    out[3] = 0; /* compat_flags */
    out[4] = seq;
    out[5] = sysid;
    out[6] = compid;
    out[7] = (uint8_t)msgid;
    out[8] = (uint8_t)(msgid >> 8);
    out[9] = (uint8_t)(msgid >> 16);
    memcpy(out + CDSPD_MAVLINK_HEADER, payload, len);
    x = (uint8_t)extra;
    crc = cdspd_mavlink_crc(0xFFFF, out + 1, CDSPD_MAVLINK_HEADER - 1 + len);
    crc = cdspd_mavlink_crc(crc, &x, 1);
    out[CDSPD_MAVLINK_HEADER + len] = (uint8_t)crc;
    out[CDSPD_MAVLINK_HEADER + len + 1] = (uint8_t)(crc >> 8);
    return CDSPD_MAVLINK_HEADER + len + 2;
}

cdspd_mavlink_result cdspd_mavlink_frame_decode(const uint8_t *buf, size_t len,
                                                cdspd_mavlink_frame *f, size_t *used)
{
    size_t n, total;
    int extra;
    uint16_t crc;
    uint8_t x;
    const uint8_t *start = len ? memchr(buf, CDSPD_MAVLINK_STX, len) : NULL;

    if (!start) {
        *used = len;
        return CDSPD_MAVLINK_JUNK;
    }
    if (start != buf) {
        *used = (size_t)(start - buf);
        return CDSPD_MAVLINK_JUNK;
    }
    *used = 0;
    if (len < CDSPD_MAVLINK_HEADER)
        return CDSPD_MAVLINK_MORE;
    n = buf[1];
    total = CDSPD_MAVLINK_HEADER + n + 2 +
            ((buf[2] & CDSPD_MAVLINK_IFLAG_SIGNED) ? CDSPD_MAVLINK_SIGNATURE : 0);
    if (len < total)
        return CDSPD_MAVLINK_MORE;
    f->len = (uint8_t)n;
    f->incompat = buf[2];
    f->compat = buf[3];
    f->seq = buf[4];
    f->sysid = buf[5];
    f->compid = buf[6];
    f->msgid = (uint32_t)buf[7] | (uint32_t)buf[8] << 8 | (uint32_t)buf[9] << 16;
    f->crc = (uint16_t)(buf[CDSPD_MAVLINK_HEADER + n] | buf[CDSPD_MAVLINK_HEADER + n + 1] << 8);
    extra = cdspd_mavlink_crc_extra(f->msgid);
    if (extra < 0) {
        *used = total;
        return CDSPD_MAVLINK_UNKNOWN;
    }
    x = (uint8_t)extra;
    crc = cdspd_mavlink_crc(0xFFFF, buf + 1, CDSPD_MAVLINK_HEADER - 1 + n);
    crc = cdspd_mavlink_crc(crc, &x, 1);
    if (crc != f->crc) {
        *used = 1;
        return CDSPD_MAVLINK_BAD_CRC;
    }
    memset(f->payload, 0, sizeof f->payload);
    memcpy(f->payload, buf + CDSPD_MAVLINK_HEADER, n);
    *used = total;
    return CDSPD_MAVLINK_OK;
}
