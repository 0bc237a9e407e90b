#!/usr/bin/env python3
"""Seeds and regression inputs of the udp_target fuzz target (fuzz/udp_target_fuzz.cpp).

Each input: one mode byte (bit 0: the target has a key), then records
[host byte: bits 0-1 host, bit 2 seal with the key, bits 3-7 time step][length][datagram].
A request's session field 0xFFFFFFFF is replaced by the harness with the id the host's last hello
reply gave, so that the seeds reach the session's code.

    python3 scripts/fuzz/make_udp_seeds.py        # writes fuzz/seeds/udp_target and fuzz/regression/udp_target
"""
import os
import struct

MAGIC, VERSION = 0x315A4250, 2
HELLO, IO, BYE, SAFE, RESET = 1, 3, 5, 7, 9
MINE = 0xFFFFFFFF


def request(kind, sequence=0, u=0.0, flags=0, session=MINE):
    return struct.pack("<IHHQdII", MAGIC, VERSION, kind, sequence, u, flags, 0 if kind == HELLO else session)


def record(host, datagram, seal=False, step=0):
    return bytes([(host & 3) | (4 if seal else 0) | (step << 3), len(datagram)]) + datagram


def session(host, commands, seal=False, bye=True, first=1):
    out = record(host, request(HELLO, u=10e3), seal)
    for k, u in enumerate(commands):
        out += record(host, request(IO, first + k, u), seal)
    if bye:
        out += record(host, request(BYE, first + len(commands)), seal)
    return out


def main():
    root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "fuzz")
    seeds = {
        # One host's session: a ramp up to 150 V at the stacks (7.5 V at the DAC).
        "one_session.bin": b"\x00" + session(0, [0.5 * k for k in range(16)]),
        # A second host's hello and commands during the first's session (issue 35: both were obeyed).
        "two_hosts.bin": b"\x00" + record(0, request(HELLO, u=10e3)) + record(0, request(IO, 1, 1.0))
        + record(1, request(HELLO, u=10e3)) + record(1, request(IO, 1, 7.5)) + record(1, request(IO, 1, 7.5, session=0))
        + record(0, request(IO, 2, 1.5)) + record(0, request(BYE, 3)),
        # The watchdog's safe request, a hello that must not clear it, then the session's reset.
        "safe_reset.bin": b"\x00" + session(0, [7.5] * 4, bye=False) + record(0, request(SAFE, flags=1))
        + record(0, request(IO, 5, 7.5)) + record(0, request(BYE, 6)) + record(1, request(HELLO, u=10e3))
        + record(1, request(IO, 1, 7.5)) + record(1, request(RESET)) + record(1, request(IO, 2, 7.5)),
        # Commands beyond the limits: 1e300, NaN, -inf, a jump of 150 V.
        "limits.bin": b"\x00" + session(0, [1e300, float("nan"), float("-inf"), -1.0, 7.5, -1.0]),
        # With a key: sealed datagrams and an unsealed one from another host.
        "keyed.bin": b"\x01" + session(0, [0.5, 1.0, 1.5], seal=True) + record(1, request(HELLO, u=10e3)),
        # A host silent for longer than the session time-out after its first command.
        "silent_host.bin": b"\x00" + record(0, request(HELLO, u=10e3)) + record(0, request(IO, 1, 1.0))
        + record(2, request(HELLO, u=10e3), step=31) + record(0, request(IO, 2, 1.0)) + record(2, request(IO, 1, 1.0)),
    }
    regression = {
        # Issue 35: a hello from another port cleared the latched safe state; then 150 V.
        "hello_clears_safe_state.bin": seeds["safe_reset.bin"],
        "second_host_steps_the_bench.bin": seeds["two_hosts.bin"],
        # A replayed (old) sequence number.
        "replayed_sequence.bin": b"\x00" + record(0, request(HELLO, u=10e3)) + record(0, request(IO, 1, 7.5))
        + record(0, request(IO, 1, 7.5)) + record(0, request(IO, 0, 7.5)),
    }
    for folder, files in (("seeds", seeds), ("regression", regression)):
        d = os.path.join(root, folder, "udp_target")
        os.makedirs(d, exist_ok=True)
        for name, data in files.items():
            with open(os.path.join(d, name), "wb") as f:
                f.write(data)


if __name__ == "__main__":
    main()
