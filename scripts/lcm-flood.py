#!/usr/bin/env python3
"""Floods one LCM channel with garbage (a load generator for scripts/jitter-bench.sh).

Sends LCM small-message packets (magic "LC02", sequence number, channel name, payload) to a UDP
multicast group as fast as it can, or at --rate messages per second, for --seconds. The payload is
random bytes, so the receiver decodes and rejects each message (or drops it undecoded once its
per-tick bound is reached). Use it inside a private network namespace, as the bench does.

  scripts/lcm-flood.py --url 'udpm://239.255.76.67:7900?ttl=0' --channel RS_GROUND_CMD --seconds 10
"""
import argparse
import os
import re
import socket
import struct
import sys
import time


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--url", required=True, help="udpm://GROUP:PORT?ttl=0")
    ap.add_argument("--channel", default="RS_GROUND_CMD")
    ap.add_argument("--seconds", type=float, default=10.0)
    ap.add_argument("--rate", type=float, default=0.0, help="messages per second (0: as fast as possible)")
    ap.add_argument("--size", type=int, default=200, help="payload bytes")
    a = ap.parse_args()
    m = re.match(r"udpm://([0-9.]+):([0-9]+)", a.url)
    if not m:
        print(f"lcm-flood: --url {a.url!r}: expected udpm://GROUP:PORT", file=sys.stderr)
        return 2
    group, port = m.group(1), int(m.group(2))
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 0)
    s.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
    head = a.channel.encode() + b"\0"
    payloads = [os.urandom(a.size) for _ in range(64)]
    end = time.monotonic() + a.seconds
    period = 1.0 / a.rate if a.rate > 0 else 0.0
    sent = 0
    next_t = time.monotonic()
    while True:
        now = time.monotonic()
        if now >= end:
            break
        if period > 0.0:
            if now < next_t:
                time.sleep(next_t - now)
            next_t += period
        pkt = struct.pack(">II", 0x4C433032, sent & 0xFFFFFFFF) + head + payloads[sent % 64]
        try:
            s.sendto(pkt, (group, port))
            sent += 1
        except OSError:
            pass  # a full socket buffer: keep going
    print(f"lcm-flood: {sent} messages on {a.channel} in {a.seconds:g} s ({sent / a.seconds:.0f}/s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
