"""A small LCM UDP-multicast transport in pure Python (standard library only).

For machines where no Python LCM binding is installed (Debian 12 packages LCM 1.3.1 for C, C++
and Java, not for Python). It speaks the same datagrams as LCM's udpm provider, so it talks to
rths's C++ participants, lcm-spy, lcm-logger and any LCM program on the same URL. It offers the
part of the `lcm.LCM` API an rths participant needs:

    lc = LcmUdpm("udpm://239.255.76.67:7667?ttl=0")
    lc.subscribe("RTHS_COMMAND", on_command)    # on_command(channel: str, data: bytes)
    lc.publish("RTHS_MEASURED", data)
    lc.handle_timeout(10)                       # > 0 if a message was handled, 0 on timeout
    lc.close()

The wire format is taken from LCM 1.3.1, lcm/lcm_udpm.c (lcm_udpm_publish, _recv_short_message,
_recv_message_fragment, _setup_recv_parts, lcm_udpm_create) and lcm/udpm_util.h (the headers
lcm2_header_short_t / lcm2_header_long_t and the size limits), tag v1.3.1 of
github.com/lcm-proj/lcm; docs/participant.md, "Without an LCM binding: the wire format",
describes it. All integers are big-endian.

  LC02, a message that fits in one datagram:
      uint32 magic 0x4c433032 ("LC02") | uint32 sequence number | channel | NUL | payload
  LC03, one fragment of a larger message:
      uint32 magic 0x4c433033 ("LC03") | uint32 sequence number | uint32 payload size |
      uint32 fragment offset | uint16 fragment number | uint16 fragment count |
      (fragment 0 only: channel | NUL) | this fragment's part of the payload

Differences from LCM's own provider, on purpose: subscribe() takes an exact channel name (LCM
takes a regular expression); one socket sends and receives (LCM uses two); `recv_buf_size` is
ignored; `port_per_channel=1` (an rths extension: one port per channel) is not supported and is
refused with a clear error. Like LCM, this transport hears its own messages (multicast loopback is
on, so other processes on this host hear them too): the caller must ignore its own echoes.
"""

import select
import socket
import struct
import sys
import time
import urllib.parse

MAGIC_SHORT = 0x4C433032  # "LC02": a whole message in one datagram
MAGIC_LONG = 0x4C433033  # "LC03": one fragment of a message
SHORT_HEADER = struct.Struct(">II")  # magic, sequence number
LONG_HEADER = struct.Struct(">IIIIHH")  # magic, seqno, payload size, offset, fragment no, count
MAX_CHANNEL = 63  # LCM_MAX_CHANNEL_NAME_LENGTH [bytes]
SHORT_MESSAGE_MAX = 65499  # LCM_SHORT_MESSAGE_MAX_SIZE: channel + NUL + payload, in one LC02 [bytes]
FRAGMENT_MAX_PAYLOAD = 65487  # LCM_FRAGMENT_MAX_PAYLOAD: channel (fragment 0) + payload per LC03 [bytes]
MAX_MESSAGE = 1 << 28  # LCM_MAX_MESSAGE_SIZE: larger announced payloads are dropped [bytes]
DEFAULT_GROUP, DEFAULT_PORT, DEFAULT_TTL = "239.255.76.67", 7667, 0  # LCM 1.3.1's defaults


def parse_udpm_url(url):
    """udpm://GROUP:PORT?ttl=N -> (group, port, ttl). Raises ValueError on anything else."""
    parts = urllib.parse.urlsplit(url)
    if parts.scheme != "udpm":
        raise ValueError(f"{url}: not a udpm:// URL (expected udpm://GROUP:PORT?ttl=N)")
    host, _, port_text = parts.netloc.partition(":")
    group = host or DEFAULT_GROUP
    try:
        socket.inet_aton(group)
        port = int(port_text) if port_text else DEFAULT_PORT
    except (OSError, ValueError):
        raise ValueError(f"{url}: bad multicast group or port (expected udpm://GROUP:PORT?ttl=N)") from None
    if not 0 < port < 65536 or not socket.inet_aton(group)[0] & 0xF0 == 0xE0:
        raise ValueError(f"{url}: the group must be an IPv4 multicast address (224.0.0.0/4) and the port 1..65535")
    ttl = DEFAULT_TTL
    for key, value in urllib.parse.parse_qsl(parts.query):
        if key == "ttl":
            ttl = int(value)
            if not 0 <= ttl <= 255:
                raise ValueError(f"{url}: ttl must be 0..255")
        elif key == "port_per_channel":
            if value not in ("0", ""):
                raise ValueError(f"{url}: port_per_channel=1 (one UDP port per channel) is not supported by "
                                 "lcm_udpm.py; run rths without --port-per-channel, or install a Python LCM binding")
        elif key == "recv_buf_size":
            pass  # the kernel's default receive buffer is enough for rths's small messages
        else:
            print(f"lcm_udpm: ignoring unknown URL option {key}", file=sys.stderr)
    return group, port, ttl


class LcmUdpm:
    """One UDP socket bound to the run's port, joined to its multicast group (see the module doc)."""

    def __init__(self, url):
        self.group, self.port, ttl = parse_udpm_url(url)
        self._handlers = {}  # channel -> callback(channel, data)
        self._seqno = 0  # uint32 counter of messages sent (LCM's msg_seqno)
        self._fragments = {}  # sender (ip, port) -> message being reassembled (one per sender, as LCM)
        s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
        try:
            # Every process of the run binds the same port: allow sharing it.
            s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            if hasattr(socket, "SO_REUSEPORT"):
                s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEPORT, 1)
            s.bind(("", self.port))  # INADDR_ANY:port, like LCM
            # Join the group on the default interface (INADDR_ANY lets the routing table choose).
            mreq = struct.pack("4s4s", socket.inet_aton(self.group), socket.inet_aton("0.0.0.0"))
            s.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP, mreq)
            # Loopback on: the other participants on this host hear what we send (and so do we).
            s.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
            # ttl=0: never leaves this host; ttl=1: this LAN (docs/two_hosts.md).
            s.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, ttl)
        except OSError as e:
            s.close()
            raise OSError(f"lcm_udpm: cannot open {url}: {e} (is there a multicast route? "
                          "ip route add 224.0.0.0/4 dev lo, see scripts/bootstrap.sh)") from e
        self._sock = s

    def fileno(self):
        return self._sock.fileno()

    def close(self):
        self._sock.close()

    def subscribe(self, channel, callback):
        """callback(channel, data) for every message on `channel` (an exact name, not a regex)."""
        self._handlers[channel] = callback

    def unsubscribe(self, channel):
        self._handlers.pop(channel, None)

    def publish(self, channel, data):
        """Sends `data` (bytes) on `channel`: one LC02 datagram, or LC03 fragments if it is large."""
        name = channel.encode("ascii")
        if len(name) > MAX_CHANNEL:
            raise ValueError(f"channel name longer than {MAX_CHANNEL} bytes: {channel}")
        dest = (self.group, self.port)
        seqno = self._seqno
        self._seqno = (self._seqno + 1) & 0xFFFFFFFF
        if len(name) + 1 + len(data) <= SHORT_MESSAGE_MAX:
            self._sock.sendto(SHORT_HEADER.pack(MAGIC_SHORT, seqno) + name + b"\0" + data, dest)
            return
        # Fragments: fragment 0 carries the channel and as much payload as fits beside it; the
        # others FRAGMENT_MAX_PAYLOAD bytes each; the offset counts payload bytes only.
        count = -(-(len(name) + 1 + len(data)) // FRAGMENT_MAX_PAYLOAD)
        if count > 65535:
            raise ValueError(f"message too large for LCM: {len(data)} bytes")
        first = FRAGMENT_MAX_PAYLOAD - (len(name) + 1)
        header = LONG_HEADER.pack(MAGIC_LONG, seqno, len(data), 0, 0, count)
        self._sock.sendto(header + name + b"\0" + data[:first], dest)
        offset = first
        for number in range(1, count):
            part = data[offset:offset + FRAGMENT_MAX_PAYLOAD]
            self._sock.sendto(LONG_HEADER.pack(MAGIC_LONG, seqno, len(data), offset, number, count) + part, dest)
            offset += len(part)

    def handle_timeout(self, timeout_ms):
        """Waits up to timeout_ms [ms] for one complete message of a subscribed channel and calls
        its callback. Returns 1 if a message was handled, 0 on timeout (like lcm.LCM's)."""
        deadline = time.monotonic() + max(0.0, timeout_ms) / 1000.0
        while True:
            ready, _, _ = select.select([self._sock], [], [], max(0.0, deadline - time.monotonic()))
            if not ready:
                return 0
            packet, sender = self._sock.recvfrom(65536)
            message = self._receive(packet, sender)
            if message is not None:
                channel, data = message
                self._handlers[channel](channel, data)
                return 1

    def _receive(self, packet, sender):
        """One datagram -> (channel, payload) of a complete message we subscribe to, or None."""
        if len(packet) < SHORT_HEADER.size:
            return None
        magic, seqno = SHORT_HEADER.unpack_from(packet)
        if magic == MAGIC_SHORT:
            end = packet.find(b"\0", SHORT_HEADER.size)
            if end < 0 or end - SHORT_HEADER.size > MAX_CHANNEL:
                return None
            channel = packet[SHORT_HEADER.size:end].decode("ascii", "replace")
            if channel not in self._handlers:
                return None  # not ours (our own echoes of unsubscribed channels end here)
            return channel, packet[end + 1:]
        if magic != MAGIC_LONG or len(packet) < LONG_HEADER.size:
            return None
        _, seqno, size, offset, number, count = LONG_HEADER.unpack_from(packet)
        body = LONG_HEADER.size
        buf = self._fragments.get(sender)
        if buf is not None and (buf["seqno"] != seqno or len(buf["data"]) != size):
            del self._fragments[sender]  # a newer message: the old one lost a fragment
            buf = None
        if size > MAX_MESSAGE:
            return None
        if buf is None:
            if number != 0:
                return None  # LCM needs fragment 0 first (it names the channel)
            end = packet.find(b"\0", body)
            if end < 0 or end - body > MAX_CHANNEL:
                return None
            channel = packet[body:end].decode("ascii", "replace")
            if channel not in self._handlers:
                return None
            buf = {"channel": channel, "seqno": seqno, "data": bytearray(size), "remaining": count}
            self._fragments[sender] = buf
            body = end + 1
        part = packet[body:]
        if offset + len(part) > size:
            del self._fragments[sender]  # an invalid fragment spoils the message
            return None
        buf["data"][offset:offset + len(part)] = part
        buf["remaining"] -= 1
        if buf["remaining"] > 0:
            return None
        del self._fragments[sender]
        return buf["channel"], bytes(buf["data"])

