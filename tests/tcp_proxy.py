"""A TCP forwarder between one station and the server, which a test can cut and restore: a network outage.

    proxy = TcpProxy(server_port)      # listens on 127.0.0.1:proxy.port
    proxy.cut()                        # open connections are dropped, new ones refused (ECONNREFUSED)
    proxy.restore()                    # listening again, on the same port
"""
from __future__ import annotations

import contextlib
import socket
import threading


class TcpProxy:
    def __init__(self, target_port: int, target_host: str = "127.0.0.1"):
        self.target = (target_host, target_port)
        self._lock = threading.Lock()
        self._open: set[socket.socket] = set()
        self._listener: socket.socket | None = None
        self._kept: list[socket.socket] = []    # the server's sides cut_station_side left open and silent
        self._upstream: set[socket.socket] = set()      # the server's side of each connection
        self.port = 0
        self.restore()

    def restore(self) -> None:
        listener = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        listener.bind(("127.0.0.1", self.port))
        listener.listen(32)
        self.port = listener.getsockname()[1]
        self._listener = listener
        threading.Thread(target=self._accept, args=(listener,), daemon=True).start()

    def cut(self) -> None:
        with self._lock:
            listener, self._listener = self._listener, None
            sockets, self._open = self._open, set()
        if listener is not None:
            with contextlib.suppress(OSError):
                listener.shutdown(socket.SHUT_RDWR)     # wakes the accepting thread: close alone leaves the port
            listener.close()                            # bound while it waits, and restore() finds it in use
        for s in sockets:
            try:
                s.shutdown(socket.SHUT_RDWR)
            except OSError:
                pass
            s.close()

    close = cut

    def cut_station_side(self) -> None:
        """A cable pulled at the station: its side of every open connection is dropped, the server's side is
        left open and silent, so the server keeps the session (and its open transaction) until its own
        timeouts end it. New connections are refused until restore()."""
        with self._lock:
            listener, self._listener = self._listener, None
            sockets, self._open = self._open, set()
            self._kept += [s for s in sockets if s in self._upstream]
        if listener is not None:
            with contextlib.suppress(OSError):
                listener.shutdown(socket.SHUT_RDWR)     # wakes the accepting thread, so the port is free at once
            listener.close()
        for s in sockets:
            if s not in self._kept:
                try:
                    s.shutdown(socket.SHUT_RDWR)        # wakes the pumps; the station reads the end
                except OSError:
                    pass
                s.close()

    def _accept(self, listener: socket.socket) -> None:
        while True:
            try:
                client, _ = listener.accept()
            except OSError:
                return          # cut
            try:
                upstream = socket.create_connection(self.target, timeout=10)
                upstream.settimeout(None)
            except OSError:
                client.close()
                continue
            with self._lock:
                if self._listener is not listener:
                    client.close()
                    upstream.close()
                    return
                self._open |= {client, upstream}
                self._upstream.add(upstream)
            for a, b in ((client, upstream), (upstream, client)):
                threading.Thread(target=self._pump, args=(a, b), daemon=True).start()

    def _pump(self, source: socket.socket, sink: socket.socket) -> None:
        try:
            while data := source.recv(65536):
                sink.sendall(data)
        except OSError:
            pass
        if source in self._kept or sink in self._kept:
            return          # the server is not told: its side stays open, as behind a pulled cable
        for s in (source, sink):
            try:
                s.shutdown(socket.SHUT_RDWR)
            except OSError:
                pass
