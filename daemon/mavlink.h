/*
 * mavlink.h - MAVLink 2 framing and the few common-dialect messages cdspd
 * sends (HEARTBEAT, LANDING_TARGET, DEBUG_VECT), written from the protocol
 * specification (the wire facts are in docs/mavlink.md): no MAVLink library,
 * nothing beyond libc, no allocation, no state. The daemon encodes with it
 * (daemon/mavout.c); the tests and receivers decode with it.
 *
 * A frame (unsigned; 12 bytes + payload):
 *   0xFD, len, incompat_flags, compat_flags, seq, sysid, compid,
 *   msgid (3 bytes, little endian), payload[len], crc (2 bytes, little endian)
 * crc: CRC-16/MCRF4XX (init 0xFFFF, reflected polynomial 0x8408, no final
 * xor) over every byte after the magic up to the end of the payload, then
 * over the message's CRC_EXTRA byte (a hash of its definition, so sender and
 * receiver agree on the field layout). Payload fields are little endian in
 * wire order (base fields sorted by type size, largest first, stable;
 * extension fields after them in declaration order); trailing zero bytes of
 * the payload are not sent (at least one byte is) and a receiver reads the
 * missing tail as zeros.
 */
#ifndef CDSPD_MAVLINK_H
#define CDSPD_MAVLINK_H

#include <stddef.h>
#include <stdint.h>

#define CDSPD_MAVLINK_STX 0xFD
#define CDSPD_MAVLINK_HEADER 10         /* magic .. msgid */
#define CDSPD_MAVLINK_SIGNATURE 13      /* after the crc when incompat bit 0 is set */
#define CDSPD_MAVLINK_MAX_PAYLOAD 255
#define CDSPD_MAVLINK_MAX_FRAME (CDSPD_MAVLINK_HEADER + CDSPD_MAVLINK_MAX_PAYLOAD + 2 + \
                                 CDSPD_MAVLINK_SIGNATURE)
#define CDSPD_MAVLINK_IFLAG_SIGNED 0x01u

/* Message ids, CRC_EXTRA and full payload sizes (common dialect). */
#define CDSPD_MAVLINK_ID_HEARTBEAT 0u
#define CDSPD_MAVLINK_ID_LANDING_TARGET 149u
#define CDSPD_MAVLINK_ID_DEBUG_VECT 250u
#define CDSPD_MAVLINK_ID_NAMED_VALUE_FLOAT 251u
#define CDSPD_MAVLINK_LEN_HEARTBEAT 9
#define CDSPD_MAVLINK_LEN_LANDING_TARGET 60
#define CDSPD_MAVLINK_LEN_DEBUG_VECT 30

/* Enum values used. */
#define CDSPD_MAV_TYPE_ONBOARD_CONTROLLER 18
#define CDSPD_MAV_AUTOPILOT_INVALID 8
#define CDSPD_MAV_STATE_BOOT 1
#define CDSPD_MAV_STATE_ACTIVE 4
#define CDSPD_MAV_STATE_CRITICAL 5
#define CDSPD_MAV_COMP_ID_ONBOARD_COMPUTER 191
#define CDSPD_MAV_FRAME_BODY_FRD 12
#define CDSPD_LANDING_TARGET_TYPE_VISION_OTHER 3
#define CDSPD_MAVLINK_VERSION 3          /* HEARTBEAT.mavlink_version */

typedef struct {
    uint32_t custom_mode;
    uint8_t type, autopilot, base_mode, system_status, mavlink_version;
} cdspd_mavlink_heartbeat;

typedef struct {
    uint64_t time_usec;       /* us */
    float angle_x, angle_y;   /* rad, offsets of the target from the image centre */
    float distance;           /* m */
    float size_x, size_y;     /* rad */
    uint8_t target_num, frame;
    /* extensions */
    float x, y, z;            /* m, in frame */
    float q[4];               /* w, x, y, z */
    uint8_t type, position_valid;
} cdspd_mavlink_landing_target;

typedef struct {
    uint64_t time_usec;
    float x, y, z;
    char name[10];            /* not NUL-terminated when 10 long */
} cdspd_mavlink_debug_vect;

/* A decoded frame: the header fields and the payload zero-extended to
 * CDSPD_MAVLINK_MAX_PAYLOAD (len is what was on the wire). */
typedef struct {
    uint8_t len, incompat, compat, seq, sysid, compid;
    uint32_t msgid;
    uint16_t crc;
    uint8_t payload[CDSPD_MAVLINK_MAX_PAYLOAD];
} cdspd_mavlink_frame;

/* CRC-16/MCRF4XX: accumulate n bytes into crc (start from 0xFFFF). */
uint16_t cdspd_mavlink_crc(uint16_t crc, const uint8_t *p, size_t n);

/* CRC_EXTRA of a message id this module knows, -1 for any other. */
int cdspd_mavlink_crc_extra(uint32_t msgid);

/* Payloads in wire order, full length (the framing truncates): return the
 * number of bytes written into p, which must hold the message's LEN. */
size_t cdspd_mavlink_pack_heartbeat(uint8_t *p, const cdspd_mavlink_heartbeat *m);
size_t cdspd_mavlink_pack_landing_target(uint8_t *p, const cdspd_mavlink_landing_target *m);
size_t cdspd_mavlink_pack_debug_vect(uint8_t *p, const cdspd_mavlink_debug_vect *m);

/* The inverse, from a decoded frame of that id; 0, or -1 for another id. */
int cdspd_mavlink_unpack_heartbeat(const cdspd_mavlink_frame *f, cdspd_mavlink_heartbeat *m);
int cdspd_mavlink_unpack_landing_target(const cdspd_mavlink_frame *f,
                                        cdspd_mavlink_landing_target *m);
int cdspd_mavlink_unpack_debug_vect(const cdspd_mavlink_frame *f, cdspd_mavlink_debug_vect *m);

/* Frame a payload of len bytes (trailing zeros dropped) into out: returns
 * the frame's length, or 0 when out (cap bytes) is too small, len is over
 * 255 or msgid has no known CRC_EXTRA. */
size_t cdspd_mavlink_frame_encode(uint8_t *out, size_t cap, uint8_t seq, uint8_t sysid,
                                  uint8_t compid, uint32_t msgid, const uint8_t *payload,
                                  size_t len);

typedef enum {
    CDSPD_MAVLINK_OK = 0,     /* *f filled; *used bytes make the frame */
    CDSPD_MAVLINK_MORE = 1,   /* a frame starts at buf[0] but is not complete */
    CDSPD_MAVLINK_JUNK = 2,   /* buf[0 .. *used) holds no frame start: skip it */
    CDSPD_MAVLINK_BAD_CRC = 3,/* a complete frame whose crc is wrong: skip 1 byte */
    CDSPD_MAVLINK_UNKNOWN = 4 /* a frame of an id without known CRC_EXTRA: skip *used */
} cdspd_mavlink_result;

/* Decode the frame at the start of buf (len bytes): a stream reader calls
 * it in a loop, dropping *used bytes after each result but MORE. A BAD_CRC
 * sets *used to 1, so a magic byte inside a broken frame is tried next. */
cdspd_mavlink_result cdspd_mavlink_frame_decode(const uint8_t *buf, size_t len,
                                                cdspd_mavlink_frame *f, size_t *used);

#endif
