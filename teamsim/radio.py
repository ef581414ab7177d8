"""Broadcast radio: sender-tagged messages, no negotiation (Parker §2.2.3, §3.2).

Every robot with a working radio broadcasts its current outbox once per period 1/rho (the base station gave
each R-2 one 10-byte slot every 3 s). Each receiver in range gets a copy with probability 1 - loss, after
``latency`` seconds. A receiver keeps the time it last heard each sender; ``robots_present`` is the set heard
within the timeout tau. Send phases are staggered per robot from its own seeded stream, as the base station's
cyclic slots were.
"""
from __future__ import annotations

import heapq
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from teamsim.config import RadioConfig


@dataclass(frozen=True)
class Message:
    sender: str
    sent_at: float
    payload: Any


@dataclass
class _Radio:
    rng: np.random.Generator
    next_send: float
    enabled: bool = True
    outbox: Any = field(default_factory=dict)
    inbox: list = field(default_factory=list)
    last_heard: dict = field(default_factory=dict)


class RadioBus:
    def __init__(self, config: RadioConfig, rngs: dict[str, np.random.Generator]):
        """``rngs`` maps each robot name to its radio stream (phase and loss draws)."""
        self.config = config
        self.period = 1.0 / config.rate_hz
        self._radios = {name: _Radio(rng=rng, next_send=float(rng.uniform(0.0, self.period)))
                        for name, rng in rngs.items()}
        self._in_flight: list[tuple[float, int, str, Message]] = []
        self._sequence = 0

    def set_enabled(self, robot: str, enabled: bool) -> None:
        self._radios[robot].enabled = enabled

    def set_outbox(self, robot: str, payload: Any) -> None:
        """What ``robot`` will say at its next slot (the latest value replaces any earlier one)."""
        self._radios[robot].outbox = payload

    def update(self, now: float, positions: dict[str, np.ndarray]) -> list[Message]:
        """Transmit every slot due by ``now`` and deliver what has arrived. Returns the messages sent."""
        sent = []
        for name, radio in self._radios.items():
            while radio.next_send <= now + 1e-9:
                if radio.enabled:
                    message = Message(name, radio.next_send, radio.outbox)
                    self._transmit(message, positions)
                    sent.append(message)
                radio.next_send += self.period
        while self._in_flight and self._in_flight[0][0] <= now + 1e-9:
            arrival, _, receiver, message = heapq.heappop(self._in_flight)
            radio = self._radios[receiver]
            if radio.enabled:
                radio.inbox.append(message)
                radio.last_heard[message.sender] = arrival
        return sent

    def _transmit(self, message: Message, positions: dict[str, np.ndarray]) -> None:
        origin = positions.get(message.sender)
        for receiver, radio in self._radios.items():
            if receiver == message.sender:
                continue
            # One loss draw per (message, receiver), always taken, so range never shifts the stream.
            lost = radio.rng.random() < self.config.loss
            if lost:
                continue
            if math.isfinite(self.config.range):
                where = positions.get(receiver)
                if origin is None or where is None or np.hypot(*(where[:2] - origin[:2])) > self.config.range:
                    continue
            self._sequence += 1
            heapq.heappush(self._in_flight,
                           (message.sent_at + self.config.latency, self._sequence, receiver, message))

    def take_inbox(self, robot: str) -> list[Message]:
        radio = self._radios[robot]
        messages, radio.inbox = radio.inbox, []
        return messages

    def robots_present(self, robot: str, now: float) -> frozenset[str]:
        """Teammates ``robot`` has heard from within the timeout tau."""
        tau = self.config.timeout
        return frozenset(s for s, t in self._radios[robot].last_heard.items() if now - t <= tau)
