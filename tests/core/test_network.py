"""teamsim.network: 802.11 links carrying addressed, sized packets (Chand Table 5.22, §6.5), alone and in a World."""
from __future__ import annotations

import numpy as np
import pytest

import teamsim  # noqa: F401  (GL backend before mujoco)
from teamsim.controllers.base import Command
from teamsim.faults import parse_fault
from teamsim.network import Delivery, Network, NetworkConfig, Packet
from teamsim.rng import RandomStreams
from teamsim.scene import RobotSlot
from teamsim.tasks.missions.custom import CustomMission, CustomParams, custom_config
from teamsim.world import World

MBIT = 1e6
LOCAL_MAP = 8192  # bytes: one of Chand's local maps (§6.5)
NAMES = ("a", "b", "c")


def make_network(links=None, seed=1, **config):
    links = links or {name: (11 * MBIT, 100.0) for name in NAMES}
    streams = RandomStreams(seed)
    return Network(NetworkConfig(**config), links, {name: streams.get("robot", name, "radio") for name in links})


def at(*xy_pairs):
    """Positions of a, b, c, ... at the given (x, y)."""
    return {name: np.array([x, y, 0.0]) for name, (x, y) in zip(NAMES, xy_pairs)}


TOGETHER = at((0, 0), (1, 0), (2, 0))


def run(network, until, dt=0.001, positions=TOGETHER):
    """Update on a grid k*dt up to ``until``; returns {receiver: [(time taken, Delivery), ...]}."""
    got = {name: [] for name in positions}
    for k in range(round(until / dt) + 1):
        now = k * dt
        network.update(now, positions)
        for name in positions:
            got[name] += [(now, d) for d in network.take_inbox(name)]
    return got


def test_transfer_time_of_a_local_map_at_11_mbit():
    # 8192 bytes * 8 = 65536 bits; at 11e6 bit/s that is 65536 / 11e6 s.
    assert make_network().transfer_time(LOCAL_MAP, "a") == pytest.approx(0.0059578, abs=1e-7)


def test_a_packet_arrives_after_transfer_time_plus_latency():
    network = make_network(latency=0.005)
    network.set_outbox("a", [Packet("map", "m", LOCAL_MAP, to="b")])
    got = run(network, 0.02)
    (when, delivery), = got["b"]
    assert when == pytest.approx(0.011)  # first 1 ms update at or after 0.0059578 + 0.005
    assert delivery == Delivery("a", 0.0, "map", "m", LOCAL_MAP, "b")


def test_the_link_is_serial_so_packets_sent_together_arrive_one_after_the_other():
    network = make_network(latency=0.0)
    network.set_outbox("a", [Packet("map", 1, LOCAL_MAP, to="b"), Packet("map", 2, LOCAL_MAP, to="b")])
    got = run(network, 0.02)
    assert [(round(t, 3), d.payload) for t, d in got["b"]] == [(0.006, 1), (0.012, 2)]


def test_a_broadcast_reaches_every_other_robot_and_an_addressed_packet_only_its_addressee():
    network = make_network()
    network.set_outbox("a", [Packet("hello", "all", 10), Packet("map", "b only", 10, to="b")])
    got = run(network, 0.05)
    payloads = {name: [d.payload for _, d in got[name]] for name in NAMES}
    assert payloads == {"a": [], "b": ["all", "b only"], "c": ["all"]}


def test_the_shorter_of_the_two_ranges_cuts_delivery_off():
    links = {"a": (11 * MBIT, 100.0), "b": (11 * MBIT, 30.0), "c": (11 * MBIT, 100.0)}
    network = make_network(links)
    network.set_outbox("a", [Packet("hello", None, 10)])
    got = run(network, 0.05, positions=at((0, 0), (30.5, 0), (99.5, 0)))
    assert [name for name in NAMES if got[name]] == ["c"]  # b is 30.5 m away but hears only 30 m


def test_range_is_measured_to_where_the_receiver_is_at_arrival():
    network = make_network(latency=0.5)
    network.set_outbox("a", [Packet("hello", None, 10)])
    network.update(0.0, TOGETHER)
    network.update(1.0, at((0, 0), (150, 0), (2, 0)))  # b drove out of range while the packet was on its way
    assert network.take_inbox("b") == [] and len(network.take_inbox("c")) == 1


def broadcasts_heard(loss, count=400):
    network = make_network({"a": (11 * MBIT, 100.0), "b": (11 * MBIT, 100.0)}, loss=loss)
    for k in range(count):
        network.set_outbox("a", [Packet("ping", k, 10)])
        network.update(float(k), {"a": np.zeros(3), "b": np.ones(3)})
    return len(network.take_inbox("b"))


def test_loss_drops_a_seeded_share_of_copies():
    assert broadcasts_heard(loss=1.0) == 0
    assert broadcasts_heard(loss=0.0) == 399  # the last one is still on air
    assert 160 < broadcasts_heard(loss=0.5) < 240


def test_loss_draws_come_from_the_sender_and_depend_neither_on_range_nor_on_other_senders():
    def heard_from_a_by_c(b_position=(1, 0), b_talks=False):
        network = make_network(loss=0.5, latency=0.0)
        for k in range(50):
            network.set_outbox("a", [Packet("ping", k, 10)])
            network.set_outbox("b", [Packet("ping", -k, 10)] if b_talks else ())
            network.update(float(k), at((0, 0), b_position, (1, 0)))
        return [d.payload for d in network.take_inbox("c") if d.sender == "a"]

    heard = heard_from_a_by_c()
    assert heard == heard_from_a_by_c(b_position=(500, 0))  # b out of range takes the same draws
    assert heard == heard_from_a_by_c(b_talks=True)  # c's copies of b's packets draw from b's stream


@pytest.mark.parametrize("disabled", ["a", "b"])
def test_a_disabled_sender_or_receiver_delivers_nothing(disabled):
    network = make_network()
    network.set_enabled(disabled, False)
    network.set_outbox("a", [Packet("map", "m", 10, to="b")])
    assert run(network, 0.05)["b"] == []
    assert network.bytes_sent("a") == (0 if disabled == "a" else 10)  # a dead radio puts nothing on air


def test_a_sender_switched_off_while_its_packet_is_on_air_delivers_nothing():
    network = make_network(latency=0.5)
    network.set_outbox("a", [Packet("map", "m", 10, to="b")])
    network.update(0.0, TOGETHER)
    network.set_enabled("a", False)
    network.update(1.0, TOGETHER)
    assert network.take_inbox("b") == []


def test_robots_present_forgets_a_sender_after_the_timeout():
    network = make_network(timeout=2.0, latency=0.0)
    network.set_outbox("a", [Packet("hello", None, 10)])
    network.update(0.0, TOGETHER)
    network.update(0.1, TOGETHER)
    assert network.robots_present("b", 2.0) == frozenset({"a"})
    assert network.robots_present("b", 2.2) == frozenset()
    assert network.robots_present("a", 0.1) == frozenset()


def test_byte_counters_count_a_packet_once_sent_and_once_per_receiver():
    network = make_network()
    network.set_outbox("a", [Packet("map", "m", LOCAL_MAP), Packet("note", "n", 100, to="c")])
    run(network, 0.05)
    assert network.bytes_sent("a") == LOCAL_MAP + 100
    assert (network.bytes_received("b"), network.bytes_received("c")) == (LOCAL_MAP, LOCAL_MAP + 100)
    assert network.bytes_received("a") == 0


def test_each_packet_is_sent_once():
    network = make_network()
    network.set_outbox("a", [Packet("map", "m", 10)])
    first = network.update(0.0, TOGETHER)
    assert [d.payload for d in first] == ["m"] and network.update(1.0, TOGETHER) == []


def test_a_packet_to_an_unknown_robot_is_refused():
    with pytest.raises(ValueError, match="'zed'"):
        make_network().set_outbox("a", [Packet("map", "m", 10, to="zed")])


def test_the_same_seeds_give_the_same_deliveries():
    def deliveries(seed):
        network = make_network(seed=seed, loss=0.5)
        for k in range(40):
            network.set_outbox(NAMES[k % 3], [Packet("ping", k, 10)])
            network.update(float(k), TOGETHER)
        return [d.payload for name in NAMES for d in network.take_inbox(name)]

    assert deliveries(3) == deliveries(3)
    assert deliveries(3) != deliveries(4)


# ---------------------------------------------------------------- in a World


class NetworkedMission(CustomMission):
    """The custom room, with the team on 1 Mbit/s links instead of the radio."""

    def build(self, params, rng, newcomers, physics_dt):
        scene = super().build(params, rng, newcomers, physics_dt)
        scene.network = {slot.name: (1 * MBIT, 100.0) for slot in scene.robots}
        return scene


class Recorder:
    """Stands still, keeps its observations, and sends ``first`` at its first tick only."""

    def __init__(self, first=()):
        self.first, self.observations = first, []

    def __call__(self, observation):
        self.observations.append(observation)
        packets, self.first = self.first, ()
        return Command(behaviour="still", broadcast=packets)


def networked_world(tmp_path, first, faults=()):
    """Robots a (sending ``first`` at its first tick) and b, 2 m apart on 1 Mbit/s links; (world, b, events)."""
    controllers = {"a": Recorder(first), "b": Recorder()}
    params = CustomParams(room=(4.0, 4.0), robots=[RobotSlot("a", "diffdrive", -1.0, 0.0, 0.0),
                                                    RobotSlot("b", "diffdrive", 1.0, 0.0, 0.0)])
    events = []
    config = custom_config(params, out=str(tmp_path), faults=[parse_fault(f) for f in faults])
    world = World(config, NetworkedMission(lambda robot, rng: controllers[robot.name]), events=events.append)
    for _ in range(6):
        world.tick()
        world.advance(world.steps_per_tick)
    return world, controllers["b"], [e for e in events if e["event"] in ("net", "radio")]


def test_a_world_with_a_network_delivers_packets_after_their_transfer_time(tmp_path):
    local_map = np.zeros((64, 64))
    size = 31250  # bytes: 0.25 s at 1 Mbit/s
    _, b, sent = networked_world(tmp_path, [Packet("map", local_map, size)])
    # Handed over at t=0, on air from the update at 0.1 for 0.25 s, plus 5 ms: in b's observation at 0.4.
    heard = [(round(o.time, 3), o.inbox) for o in b.observations if o.inbox]
    (when, (delivery,)), = heard
    assert when == 0.4 and delivery.sender == "a" and delivery.payload is local_map
    assert b.observations[-1].robots_present == frozenset({"a"})
    assert sent == [{"t": 0.1, "event": "net", "robot": "a", "to": None, "kind": "map", "bytes": size}]


@pytest.mark.parametrize("fault", ["radio-off:a@0.1", "kill:a@0.1", "remove:a@0.1", "radio-off:b@0.2"])
def test_faults_that_silence_a_radio_silence_the_network(tmp_path, fault):
    _, b, sent = networked_world(tmp_path, [Packet("map", None, 31250)], faults=[fault])
    assert not any(o.inbox for o in b.observations)
    assert len(sent) == (1 if fault.endswith("b@0.2") else 0)  # b's radio goes off while the packet is on air
