"""Addressed, sized messages over 802.11 links (Chand §5.7 Table 5.22, §6.5; §4.6.3 for the delay model).

Chand's exploration robots exchange whole local maps (8 KB each) over 802.11b/g, not Parker's 10-byte radio
slots: what matters is how long a message of a given size takes on a link of a given bandwidth. Each robot has
one link, (bandwidth bit/s, range m). Its link is serial: a packet starts when the link is free, spends
size * 8 / bandwidth seconds on air, and arrives ``latency`` later (§4.6.3 counts transmission delay only;
processing and propagation are folded into the small latency). A receiver gets its copy if both radios are on,
it is within the shorter of the two ranges, and the copy is not lost.

The interface is :class:`teamsim.radio.RadioBus`'s, so the world can hold either: the outbox is a sequence of
:class:`Packet`, each sent once at the next update, and inboxes hold :class:`Delivery` records, which carry the
``sender``, ``sent_at`` and ``payload`` of a radio message.
"""
from __future__ import annotations

import heapq
import math
from dataclasses import dataclass, field
from typing import Any, Mapping, Sequence

import numpy as np

from teamsim.config import setting, validate


@dataclass(frozen=True)
class Packet:
    """What a controller hands over to be sent: ``to`` a robot's name, or None to every other robot."""
    kind: str
    payload: Any
    size: int  # bytes on air
    to: str | None = None

    def __post_init__(self):
        if self.size < 0:
            raise ValueError(f"packet {self.kind!r}: size must be >= 0 bytes, got {self.size}")


@dataclass(frozen=True)
class Delivery:
    """A packet as a receiver gets it (and as the network reports it sent)."""
    sender: str
    sent_at: float
    kind: str
    payload: Any
    size: int
    to: str | None


@dataclass
class NetworkConfig:
    latency: float = setting(0.005, lo=0.0, hi=60.0, meaning="delay after the last byte is on air, s")
    loss: float = setting(0.0, lo=0.0, hi=1.0, meaning="probability a packet is lost, per receiver")
    timeout: float = setting(10.0, lo=0.0, open_lo=True, hi=3600.0,
                             meaning="a sender counts as present this long after it was last heard, s")


@dataclass
class _Link:
    rng: np.random.Generator
    bandwidth: float  # bit/s
    range: float  # m
    enabled: bool = True
    free_at: float = 0.0  # when the link has finished sending everything handed to it
    outbox: tuple = ()
    inbox: list = field(default_factory=list)
    last_heard: dict = field(default_factory=dict)
    bytes_sent: int = 0
    bytes_received: int = 0


class Network:
    def __init__(self, config: NetworkConfig, links: Mapping[str, tuple[float, float]],
                 rngs: Mapping[str, np.random.Generator]):
        """``links`` maps each robot to (bandwidth bit/s, range m); ``rngs`` each robot to its loss stream."""
        validate(config)
        _check_links(links, rngs)
        self.config = config
        self._links = {name: _Link(rng=rngs[name], bandwidth=float(bandwidth), range=float(reach))
                       for name, (bandwidth, reach) in links.items()}
        self._in_flight: list[tuple[float, int, str, Delivery, np.ndarray | None]] = []
        self._sequence = 0

    def set_enabled(self, robot: str, enabled: bool) -> None:
        self._links[robot].enabled = enabled

    def set_outbox(self, robot: str, payload: Sequence[Packet] | None) -> None:
        """Packets ``robot`` sends at the next update; they replace any not yet sent."""
        packets = tuple(payload or ())
        for packet in packets:
            self._check_packet(robot, packet)
        self._links[robot].outbox = packets

    def update(self, now: float, positions: Mapping[str, np.ndarray]) -> list[Delivery]:
        """Put every queued packet on its sender's link and deliver what has arrived. Returns the packets sent."""
        sent = []
        for name, link in self._links.items():
            packets, link.outbox = link.outbox, ()
            if not link.enabled:
                continue  # a dead radio sends nothing, and does not keep it for later
            for packet in packets:
                sent.append(self._transmit(name, link, packet, now, positions.get(name)))
        while self._in_flight and self._in_flight[0][0] <= now + 1e-9:
            arrival, _, receiver, delivery, origin = heapq.heappop(self._in_flight)
            if self._reaches(delivery.sender, receiver, origin, positions.get(receiver)):
                link = self._links[receiver]
                link.inbox.append(delivery)
                link.last_heard[delivery.sender] = arrival
                link.bytes_received += delivery.size
        return sent

    def take_inbox(self, robot: str) -> list[Delivery]:
        link = self._links[robot]
        deliveries, link.inbox = link.inbox, []
        return deliveries

    def robots_present(self, robot: str, now: float) -> frozenset[str]:
        """Teammates ``robot`` has heard from within the timeout."""
        timeout = self.config.timeout
        return frozenset(s for s, t in self._links[robot].last_heard.items() if now - t <= timeout)

    def bytes_sent(self, robot: str) -> int:
        """Bytes ``robot`` has put on air (once per packet, however many receive it)."""
        return self._links[robot].bytes_sent

    def bytes_received(self, robot: str) -> int:
        """Bytes delivered to ``robot`` (Chand's communication achievement counts successful transfers)."""
        return self._links[robot].bytes_received

    def transfer_time(self, size: int, sender: str) -> float:
        """Seconds ``size`` bytes spend on ``sender``'s link (without queueing or latency)."""
        return size * 8 / self._links[sender].bandwidth

    def _check_packet(self, robot: str, packet: Any) -> None:
        if not isinstance(packet, Packet):
            raise TypeError(f"{robot} handed the network {packet!r}; the outbox is a sequence of Packet")
        if packet.to is not None and packet.to not in self._links:
            raise ValueError(f"{robot} addressed a packet to unknown robot {packet.to!r}; "
                             f"known: {', '.join(self._links)}")
        if packet.to == robot:
            raise ValueError(f"{robot} addressed a packet to itself")

    def _transmit(self, name: str, link: _Link, packet: Packet, now: float, origin: np.ndarray | None) -> Delivery:
        """Queue ``packet`` on the serial link and schedule a copy for each receiver that does not lose it."""
        start = max(now, link.free_at)
        link.free_at = start + self.transfer_time(packet.size, name)
        link.bytes_sent += packet.size
        delivery = Delivery(name, now, packet.kind, packet.payload, packet.size, packet.to)
        receivers = [packet.to] if packet.to is not None else [r for r in self._links if r != name]
        for receiver in receivers:
            # One loss draw per (packet, receiver) from the sender's stream, always taken, so range never shifts it.
            if link.rng.random() < self.config.loss:
                continue
            self._sequence += 1
            heapq.heappush(self._in_flight,
                           (link.free_at + self.config.latency, self._sequence, receiver, delivery, origin))
        return delivery

    def _reaches(self, sender: str, receiver: str, origin: np.ndarray | None, where: np.ndarray | None) -> bool:
        """Both radios on, and the receiver (where it is now) within the shorter range of where the sender was."""
        source, target = self._links[sender], self._links[receiver]
        if not (source.enabled and target.enabled):
            return False
        reach = min(source.range, target.range)
        if math.isinf(reach):
            return True
        return origin is not None and where is not None and float(np.hypot(*(where[:2] - origin[:2]))) <= reach


def _check_links(links: Mapping[str, tuple[float, float]], rngs: Mapping[str, np.random.Generator]) -> None:
    """Every robot needs a link and a stream, and every link a positive bandwidth and a range >= 0."""
    if set(links) != set(rngs):
        unlinked, unknown = sorted(set(rngs) - set(links)), sorted(set(links) - set(rngs))
        raise ValueError(f"network links and robots differ: without a link: {', '.join(unlinked) or 'none'}; "
                         f"links of unknown robots: {', '.join(unknown) or 'none'}")
    for name, (bandwidth, reach) in links.items():
        if not bandwidth > 0 or not reach >= 0:
            raise ValueError(f"network link of {name}: bandwidth must be > 0 bit/s and range >= 0 m, "
                             f"got ({bandwidth}, {reach})")
