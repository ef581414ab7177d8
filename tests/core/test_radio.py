"""Unit tests for teamsim.radio.RadioBus: rate, loss, latency, range, timeout and disabled radios."""
from __future__ import annotations

import math

import numpy as np
import pytest

from teamsim.config import RadioConfig
from teamsim.radio import RadioBus
from teamsim.rng import RandomStreams

SEED = 1234


def make_bus(names, seed=SEED, **radio):
    streams = RandomStreams(seed)
    rngs = {name: streams.get("robot", name, "radio") for name in names}
    return RadioBus(RadioConfig(**radio), rngs)


def origin_positions(names):
    return {name: np.zeros(3) for name in names}


def run(bus, names, duration, dt, positions=None, start_step=0):
    """Step the bus on a grid k*dt (no float accumulation). Returns (sent, received[name])."""
    positions = positions or origin_positions(names)
    sent, received = [], {name: [] for name in names}
    steps = int(round(duration / dt))
    for k in range(start_step, start_step + steps + 1):
        now = k * dt
        sent += bus.update(now, positions)
        for name in names:
            received[name] += bus.take_inbox(name)
    return sent, received


# ---------------------------------------------------------------- rate


@pytest.mark.parametrize("rate_hz", [1 / 3, 2.5])
def test_each_robot_sends_rate_times_duration_messages(rate_hz):
    names = ["red", "green", "blue"]
    bus = make_bus(names, rate_hz=rate_hz)
    duration = 300.0
    sent, _ = run(bus, names, duration, dt=0.1)
    for name in names:
        times = [m.sent_at for m in sent if m.sender == name]
        assert abs(len(times) - rate_hz * duration) <= 1, (name, len(times))
        # Exactly one slot per period, no bursts or gaps.
        np.testing.assert_allclose(np.diff(times), 1.0 / rate_hz, rtol=0, atol=1e-9)
        # First slot lies within the first period.
        assert 0.0 <= times[0] < 1.0 / rate_hz


def test_send_phases_are_staggered_per_robot():
    names = [f"r{i}" for i in range(6)]
    bus = make_bus(names, rate_hz=1 / 3)
    sent, _ = run(bus, names, 3.0, dt=0.1)
    first = {m.sender: m.sent_at for m in sent}
    assert set(first) == set(names)
    # Six phases drawn uniformly in [0, 3): no two robots share a slot.
    assert len({round(t, 9) for t in first.values()}) == len(names)


def test_message_is_never_sent_before_its_slot_or_after_the_update():
    names = ["a", "b"]
    bus = make_bus(names, rate_hz=4.0)
    previous = -math.inf
    for k in range(200):
        now = k * 0.07
        for message in bus.update(now, origin_positions(names)):
            assert previous - 1e-9 < message.sent_at <= now + 1e-9
        previous = now


def test_outbox_latest_payload_is_sent():
    names = ["a", "b"]
    bus = make_bus(names, rate_hz=1.0)
    bus.set_outbox("a", {"task": 1})
    bus.set_outbox("a", {"task": 2})
    _, received = run(bus, names, 2.0, dt=0.1)
    payloads = [m.payload for m in received["b"] if m.sender == "a"]
    assert payloads and all(p == {"task": 2} for p in payloads)


# ---------------------------------------------------------------- loss


def test_loss_fraction_matches_configured_probability():
    names = [f"r{i}" for i in range(5)]
    loss = 0.3
    bus = make_bus(names, rate_hz=10.0, loss=loss)
    sent, received = run(bus, names, 100.0, dt=0.1)
    pairs = len(sent) * (len(names) - 1)  # one loss draw per (message, receiver)
    delivered = sum(len(v) for v in received.values())
    lost = pairs - delivered
    assert pairs >= 19_000
    sigma = math.sqrt(pairs * loss * (1 - loss))
    # Binomial(pairs, loss): 4 sigma tolerance, fixed seed.
    assert abs(lost - pairs * loss) <= 4 * sigma, (lost, pairs * loss, sigma)


def test_loss_is_drawn_independently_per_receiver():
    names = [f"r{i}" for i in range(5)]
    loss = 0.5
    bus = make_bus(names, rate_hz=10.0, loss=loss)
    sent, received = run(bus, names, 50.0, dt=0.1)
    copies = {}
    for name in names:
        for message in received[name]:
            copies[(message.sender, message.sent_at)] = copies.get((message.sender, message.sent_at), 0) + 1
    counts = np.bincount([copies.get((m.sender, m.sent_at), 0) for m in sent], minlength=5)
    # Copies per message ~ Binomial(4, 1/2): 1/16, 4/16, 6/16, 4/16, 1/16 of 2500 messages.
    expected = len(sent) * np.array([1, 4, 6, 4, 1]) / 16
    sigma = np.sqrt(expected * (1 - expected / len(sent)))
    assert np.all(np.abs(counts - expected) <= 4 * sigma), (counts, expected)


@pytest.mark.parametrize("loss, expect_all", [(0.0, True), (1.0, False)])
def test_loss_extremes(loss, expect_all):
    names = ["a", "b", "c"]
    bus = make_bus(names, rate_hz=2.0, loss=loss)
    sent, received = run(bus, names, 20.0, dt=0.1)
    delivered = sum(len(v) for v in received.values())
    assert len(sent) > 0
    assert delivered == (len(sent) * 2 if expect_all else 0)


def test_no_robot_receives_its_own_message():
    names = ["a", "b", "c"]
    bus = make_bus(names, rate_hz=2.0)
    _, received = run(bus, names, 10.0, dt=0.1)
    for name in names:
        assert received[name]
        assert all(m.sender != name for m in received[name])


# ---------------------------------------------------------------- latency


@pytest.mark.parametrize("latency", [0.0, 0.75, 4.2])
def test_delivery_happens_exactly_latency_after_sending(latency):
    names = ["a", "b"]
    rate = 1.0
    # Pass 1: the send schedule does not depend on when update() is called, so record it.
    sent, _ = run(make_bus(names, rate_hz=rate, latency=latency), names, 20.0, dt=0.1)
    arrivals = sorted({m.sent_at + latency for m in sent})
    # Pass 2 (same seed): query just before and exactly at every arrival time.
    bus = make_bus(names, rate_hz=rate, latency=latency)
    times = sorted(set(arrivals) | {t - 1e-6 for t in arrivals} | {k * 0.1 for k in range(201)})
    delivered = []
    for now in times:
        bus.update(now, origin_positions(names))
        for name in names:
            delivered += [(now, m) for m in bus.take_inbox(name)]
    assert len(delivered) > 10
    for now, message in delivered:
        assert now == message.sent_at + latency, (now, message)
    # Every message whose arrival falls inside the run got delivered (loss = 0).
    due = [m for m in sent if m.sent_at + latency <= times[-1]]
    assert len(delivered) == len(due)


def test_message_not_in_inbox_before_latency_elapsed():
    names = ["a", "b"]
    bus = make_bus(names, rate_hz=1.0, latency=2.5)
    positions = origin_positions(names)
    sent = []
    now = 0.0
    while not any(m.sender == "a" for m in sent):
        now += 0.01
        sent += bus.update(now, positions)
    message = next(m for m in sent if m.sender == "a")
    bus.update(message.sent_at + 2.5 - 1e-4, positions)
    assert message not in bus.take_inbox("b")
    assert "a" not in bus.robots_present("b", message.sent_at + 2.5 - 1e-4)
    bus.update(message.sent_at + 2.5, positions)
    assert message in bus.take_inbox("b")
    assert "a" in bus.robots_present("b", message.sent_at + 2.5)


# ---------------------------------------------------------------- range


def test_out_of_range_receiver_hears_nothing():
    names = ["a", "near", "far"]
    # Only (x, y) counts: "near" is 50 m up in z but exactly at range in the plane.
    positions = {"a": np.array([0.0, 0.0, 0.0]),
                 "near": np.array([3.0, 4.0, 50.0]),  # exactly 5 m from a in the plane: in range
                 "far": np.array([-5.0, 0.5, 0.0])}   # 5.02 m from a, > 8 m from near: out of range
    bus = make_bus(names, rate_hz=2.0, range=5.0)
    _, received = run(bus, names, 20.0, dt=0.1, positions=positions)
    heard = {name: {m.sender for m in received[name]} for name in names}
    assert heard["near"] == {"a"}
    assert heard["a"] == {"near"}
    assert heard["far"] == set()
    assert bus.robots_present("far", 20.0) == frozenset()
    assert bus.robots_present("a", 20.0) == frozenset({"near"})


def test_infinite_range_reaches_everyone():
    names = ["a", "b"]
    positions = {"a": np.array([0.0, 0.0]), "b": np.array([1e6, -1e6])}
    bus = make_bus(names, rate_hz=2.0)
    _, received = run(bus, names, 5.0, dt=0.1, positions=positions)
    assert {m.sender for m in received["a"]} == {"b"}
    assert {m.sender for m in received["b"]} == {"a"}


# ---------------------------------------------------------------- timeout


def test_timeout_is_timeout_periods_over_rate():
    assert RadioConfig(rate_hz=1 / 3, timeout_periods=3.0).timeout == pytest.approx(9.0)
    assert RadioConfig(rate_hz=2.0, timeout_periods=5.0).timeout == pytest.approx(2.5)


@pytest.mark.parametrize("latency", [0.0, 0.5])
def test_sender_dropped_exactly_tau_after_last_heard(latency):
    names = ["a", "b"]
    rate = 1 / 3
    bus = make_bus(names, rate_hz=rate, latency=latency, timeout_periods=3.0)
    tau = 3.0 / rate
    positions = origin_positions(names)
    heard = []
    for k in range(301):  # 0 .. 30 s
        bus.update(k * 0.1, positions)
        heard += bus.take_inbox("b")
    assert bus.robots_present("b", 30.0) == frozenset({"a"})
    bus.set_enabled("a", False)
    # Let anything still in flight arrive.
    for k in range(301, 401):
        bus.update(k * 0.1, positions)
        heard += bus.take_inbox("b")
    last_arrival = max(m.sent_at for m in heard if m.sender == "a") + latency
    assert last_arrival <= 30.0 + latency + 1e-9
    # Silence from "a" from now on; "b" keeps hearing nothing new from it.
    for k in range(401, 501):
        bus.update(k * 0.1, positions)
        assert all(m.sender != "a" for m in bus.take_inbox("b"))
    assert "a" in bus.robots_present("b", last_arrival + tau - 1e-6)
    assert "a" in bus.robots_present("b", last_arrival + 0.5 * tau)
    assert "a" not in bus.robots_present("b", last_arrival + tau + 1e-6)
    assert "a" not in bus.robots_present("b", last_arrival + 10 * tau)
    # A disabled radio receives nothing either: "a" stopped hearing "b" when it went off the air.
    assert "b" not in bus.robots_present("a", 30.0 + tau + 1.0)


def test_robots_present_empty_before_anything_heard():
    names = ["a", "b"]
    bus = make_bus(names)
    assert bus.robots_present("a", 0.0) == frozenset()


# ---------------------------------------------------------------- disabled radio


def test_disabled_radio_neither_sends_nor_receives():
    names = ["a", "b", "c"]
    bus = make_bus(names, rate_hz=2.0)
    bus.set_enabled("b", False)
    sent, received = run(bus, names, 30.0, dt=0.1)
    assert all(m.sender != "b" for m in sent)
    assert received["b"] == []
    assert bus.robots_present("b", 30.0) == frozenset()
    assert {m.sender for m in received["a"]} == {"c"}
    assert {m.sender for m in received["c"]} == {"a"}
    assert bus.robots_present("a", 30.0) == frozenset({"c"})


def test_disabled_receiver_drops_messages_in_flight_and_recovers_when_enabled():
    names = ["a", "b"]
    latency = 2.0
    bus = make_bus(names, rate_hz=1.0, latency=latency)
    positions = origin_positions(names)
    sent = []
    k = 0
    while not any(m.sender == "a" for m in sent):
        k += 1
        sent += bus.update(k * 0.01, positions)
    message = next(m for m in sent if m.sender == "a")
    bus.set_enabled("b", False)        # disabled while the message is in flight
    bus.update(message.sent_at + latency, positions)
    assert bus.take_inbox("b") == []
    bus.set_enabled("b", True)
    _, received = run(bus, names, 5.0, dt=0.1, start_step=int((message.sent_at + latency) / 0.1) + 1)
    assert message not in received["b"]
    assert any(m.sender == "a" and m.sent_at > message.sent_at for m in received["b"])


def test_same_seed_gives_identical_traffic():
    names = ["a", "b", "c"]
    runs = [run(make_bus(names, rate_hz=3.0, loss=0.4), names, 20.0, dt=0.1) for _ in range(2)]
    assert runs[0] == runs[1]
    other = run(make_bus(names, seed=SEED + 1, rate_hz=3.0, loss=0.4), names, 20.0, dt=0.1)
    assert other != runs[0]
