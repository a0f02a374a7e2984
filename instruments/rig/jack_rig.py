"""The rig's JACK client "linpar-rig": the RigEngine in the process callback, and its wiring.

Ports: ``amplifier`` (input: what the workstation plays), ``voltage-sense``,
``current-sense``, ``laser-analog`` (outputs: what its sound-card inputs read).

Wiring: PortAudio's JACK client registers its ports when the workstation
opens a stream (client "PortAudio", ports in_0, in_1, ... and out_0, ...) and
connects them to the system ports when it starts it. The rig plays the part
of the cables: on every port registration (JACK's callback only wakes a
worker thread: JACK forbids server requests from its notification thread)
and every half second anyway, the worker connects, for output channel 0 and
input channels 0, 1, 2 of the stream (ports out_N / in_N in the order of N)
    <client>:out_0 -> linpar-rig:amplifier
    linpar-rig:voltage-sense -> <client>:in_0
    linpar-rig:current-sense -> <client>:in_1
    linpar-rig:laser-analog  -> <client>:in_2
for every client whose name matches ``client_pattern`` (default: PortAudio's
clients), and removes their connections to the system ports, whose dummy
signals would otherwise be mixed in. So a workstation uses the rig with the
channel map RIG_CHANNEL_MAP.

The process callback copies the amplifier input, runs the engine and writes
the three outputs; nothing else. Faults that need the callback (an xrun, a
dead client) are requests that the callback or the worker acts on.
"""
from __future__ import annotations

import re
import threading

from instruments.rig.engine import RigEngine

CLIENT_NAME = "linpar-rig"
INPUT_PORT = "amplifier"
OUTPUT_PORTS = ("voltage-sense", "current-sense", "laser-analog")   # in the order of the sound-card inputs
DEFAULT_CLIENT_PATTERN = r"PortAudio.*"
PLAYED_CHANNEL = 0   # the sound-card output the amplifier is wired to
_RESCAN_S = 0.5


class JackRig:
    def __init__(self, engine: RigEngine, server_name: str, client_pattern: str = DEFAULT_CLIENT_PATTERN,
                 on_shutdown=None):
        import jack   # the rig process only: the workstation never loads JACK-Client

        self._jack = jack
        self.engine = engine
        self.server_name = server_name
        self.client_pattern = re.compile(client_pattern)
        self._on_shutdown = on_shutdown
        self.client = jack.Client(CLIENT_NAME, use_exact_name=True, no_start_server=True, servername=server_name)
        if self.client.samplerate != engine.sample_rate:
            raise RuntimeError(f"the JACK server runs at {self.client.samplerate} Hz, the driver at "
                               f"{engine.sample_rate} Hz")
        self.inport = self.client.inports.register(INPUT_PORT)
        self.outports = [self.client.outports.register(name) for name in OUTPUT_PORTS]
        # NB: counters written by JACK's threads, read by the control thread.
        self.xruns = 0
        self.cycles = 0
        self.connections_made = 0
        self.callback_errors = 0
        self.last_error = ""
        self.shutdown_reason: str | None = None
        self._wake = threading.Event()
        self._stop = threading.Event()
        self._killed = False
        # Held while the wiring worker talks to the client and while the client is closed: closing it
        # under the worker's get_ports/connect frees what libjack is using (the rig process died on a
        # kill-client that met a rescan, and its control socket answered nothing).
        self._client_lock = threading.Lock()
        self.client.set_process_callback(self._process)
        self.client.set_xrun_callback(self._xrun)
        self.client.set_shutdown_callback(self._shutdown)
        self.client.set_port_registration_callback(self._port_changed, only_available=False)
        # PortAudio links its ports to the system ports when its stream starts, after registering them.
        self.client.set_port_connect_callback(self._connection_changed, only_available=False)
        self._worker = threading.Thread(target=self._wire_loop, name="rig-wiring", daemon=True)

    @property
    def port_names(self) -> dict[str, str]:
        return {INPUT_PORT: self.inport.name, **{p.shortname: p.name for p in self.outports}}

    def activate(self) -> None:
        self.client.activate()
        self._worker.start()

    # --- JACK threads ------------------------------------------------------
    def _process(self, frames: int) -> None:
        try:
            played = self.inport.get_array()
            out = self.engine.process(played, self.client.last_frame_time)
            self.outports[0].get_array()[:] = out.voltage
            self.outports[1].get_array()[:] = out.current
            self.outports[2].get_array()[:] = out.displacement
            self.cycles += 1
        except Exception as exc:   # keep the audio running; the control socket reports it
            self.callback_errors += 1
            self.last_error = f"{type(exc).__name__}: {exc}"
            for port in self.outports:
                port.get_array().fill(0.0)

    def _xrun(self, delay_usecs: float) -> None:
        self.xruns += 1

    def _shutdown(self, status, reason: str) -> None:
        self.shutdown_reason = reason or "the JACK server shut down"
        self._stop.set()
        self._wake.set()
        if self._on_shutdown is not None:
            self._on_shutdown(self.shutdown_reason)

    def _port_changed(self, port, register: bool) -> None:
        if register:
            self._wake.set()

    def _connection_changed(self, a, b, connect: bool) -> None:
        if connect:    # only new links can need undoing (PortAudio's links to the system ports)
            self._wake.set()

    # --- the wiring worker -----------------------------------------------
    def _wire_loop(self) -> None:
        while not self._stop.is_set():
            self._wake.wait(_RESCAN_S)
            self._wake.clear()
            with self._client_lock:
                if self._stop.is_set() or self._killed:
                    break
                try:
                    self.wire()
                except self._jack.JackError as exc:   # a port that vanished between listing and connecting
                    self.last_error = f"wiring: {exc}"

    def wire(self) -> int:
        """Connect every matching client's ports to the rig (idempotent); the number of new connections."""
        made = 0
        for inputs, outputs in self._workstation_ports().values():
            if len(outputs) > PLAYED_CHANNEL:
                made += self._connect(outputs[PLAYED_CHANNEL], self.inport)
            for rig_port, their_port in zip(self.outports, inputs):
                made += self._connect(rig_port, their_port)
        self.connections_made += made
        return made

    def _workstation_ports(self) -> dict[str, tuple[list, list]]:
        """Client name -> (its capture ports, its playback ports), each in channel order.

        PortAudio numbers its ports on from the previous stream's (a second
        stream of the same process has in_3, in_4, ...), so the channel is the
        rank of the number among the client's current ports, not the number.
        """
        found: dict[str, tuple[list, list]] = {}
        for port in self.client.get_ports(is_audio=True):
            client_name, _, short = port.name.partition(":")
            match = re.fullmatch(r"(in|out)_(\d+)", short)
            if client_name == CLIENT_NAME or not match or not self.client_pattern.fullmatch(client_name):
                continue
            inputs, outputs = found.setdefault(client_name, ([], []))
            if match.group(1) == "in" and port.is_input:
                inputs.append((int(match.group(2)), port))
            elif match.group(1) == "out" and port.is_output:
                outputs.append((int(match.group(2)), port))
        return {name: ([p for _, p in sorted(ins, key=lambda t: t[0])], [p for _, p in sorted(outs, key=lambda t: t[0])])
                for name, (ins, outs) in found.items()}

    def _connect(self, source, destination) -> int:
        """source -> destination, once; the workstation's end loses its links to the system ports."""
        theirs = destination if source.name.startswith(f"{CLIENT_NAME}:") else source
        for other in self.client.get_all_connections(theirs):
            if other.name.startswith("system:"):
                if theirs.is_input:
                    self.client.disconnect(other, theirs)
                else:
                    self.client.disconnect(theirs, other)
        if destination.name in {p.name for p in self.client.get_all_connections(source)}:
            return 0
        self.client.connect(source, destination)
        return 1

    def connections(self) -> dict[str, list[str]]:
        ports = [self.inport, *self.outports]
        return {p.shortname: sorted(q.name for q in self.client.get_all_connections(p)) for p in ports}

    # --- faults and shutdown ---------------------------------------------
    def inject_xrun(self, seconds: float = 0.1) -> None:
        """The next process callback overruns by ``seconds`` (JACK reports an xrun to every client)."""
        self.engine.request_stall(seconds)

    def kill_client(self) -> None:
        """The rig's JACK client goes away (as if it crashed); the rig process stays up."""
        self._stop.set()
        self._wake.set()
        with self._client_lock:
            self._killed = True
            try:
                self.client.deactivate()
            finally:
                self.client.close()

    @property
    def alive(self) -> bool:
        return not self._killed and self.shutdown_reason is None

    def close(self) -> None:
        self._stop.set()
        self._wake.set()
        if self._worker.is_alive():
            self._worker.join(2.0)
        with self._client_lock:
            if not self._killed and self.shutdown_reason is None:
                self._killed = True
                try:
                    self.client.deactivate()
                    self.client.close()
                except self._jack.JackError:
                    pass

