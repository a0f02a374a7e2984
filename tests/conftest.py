"""Session-wide fixtures. Keep each one small, documented, and lazy (nothing runs unless a test asks)."""
from __future__ import annotations

import os
import shutil
import sys
from collections import Counter

import pytest

from app.blas_threads import one_blas_thread

# One BLAS thread per test process (its workers and subprocesses inherit it). OpenBLAS starts a thread per core
# and spins them while it waits; with make test's three workers on two cores they spun against each other: three
# noise seeds of the large-signal band test took 29.8 s of CPU with two threads, 4.3 s with one, same results.
# Set here, before anything imports numpy, as linpar itself does (app/blas_threads.py); a value the user set stands.
one_blas_thread()


@pytest.fixture(scope="session", autouse=True)
def crash_reports(tmp_path_factory):
    """Crash reports (app.crash_report) of the whole session go to a folder of its own, not ~/.cache."""
    folder = tmp_path_factory.mktemp("crash-reports")
    saved = os.environ.get("LINPAR_CACHE")
    os.environ["LINPAR_CACHE"] = str(folder)
    yield folder
    if saved is None:
        os.environ.pop("LINPAR_CACHE", None)
    else:
        os.environ["LINPAR_CACHE"] = saved


@pytest.fixture(scope="session")
def virtual_rig(tmp_path_factory):
    """The virtual rig (instruments.rig) on a JACK server of its own, for the whole session.

    Yields an instruments.rig.manager.RigHandle: ``.state`` has the JACK
    server's name, the calibration and the channel map that match the rig;
    ``.command("fault", set=[...])`` changes its faults (clear them after).
    Skipped only when jackd is not installed (Debian package jackd2, which
    tools/system-packages.sh installs). At the end PortAudio is released
    before the rig stops: PortAudio aborts the process if its JACK server
    vanishes under it (instruments/audio/portaudio.py).
    """
    if shutil.which("jackd") is None:
        pytest.skip("jackd is not installed: install the Debian package jackd2 (tools/system-packages.sh)")
    from instruments.audio import portaudio
    from instruments.rig.manager import start_rig, stop_rig

    runtime_dir = tmp_path_factory.mktemp("rig")
    name = f"linpar-test-{os.getpid()}"
    handle = start_rig(name, runtime_dir=runtime_dir, seed=1)
    try:
        yield handle
    finally:
        portaudio.release()
        stop_rig(name, runtime_dir=runtime_dir)


@pytest.fixture(autouse=True)
def _no_user_effects(tmp_path_factory, monkeypatch):
    """Effects of the user's own come from an empty folder, never the real one, and none outlive a test.

    The CLI registers the user folder's effects in the process (analysis.effects.registry), and tests
    run it in-process: without this, one test's effect file would join the next test's diagnosis.
    """
    from analysis.effects import registry
    monkeypatch.setenv(registry.FOLDER_ENV, str(tmp_path_factory.getbasetemp() / "no-user-effects"))
    yield
    registry.clear()


# --- a PostgreSQL server for the archive's second back end ----------------------------------------------------

_PG_DATABASES = __import__("itertools").count(1)
PG_USERS = {"station_a": "operator", "station_b": "operator", "station_c": "operator", "eva": "engineer",
            "audrey": "auditor"}


@pytest.fixture(scope="session")
def pg_server():
    """A throw-away PostgreSQL server for the session (tests/pg_server.py).

    Skipped, saying what to install, only when PostgreSQL is not installed; a server that is installed
    but does not start is an error, never a skip. With $LINPAR_REQUIRE_POSTGRES=1 (.ci/run sets it) a
    missing PostgreSQL fails the tests too: CI runs them, it never passes them by skipping.
    """
    from tests.pg_server import PostgresServer, missing_reason
    reason = missing_reason()
    if reason and os.environ.get("LINPAR_REQUIRE_POSTGRES") == "1":
        pytest.fail(f"{reason} ($LINPAR_REQUIRE_POSTGRES=1: CI must run them)", pytrace=False)
    if reason:
        pytest.skip(reason)
    server = PostgresServer.start()
    try:
        yield server
    finally:
        server.stop()


class PgDatabase:
    """One test's database on the session's server, set up as `linpar archive setup` does (PG_USERS)."""

    def __init__(self, server, name: str):
        self.server = server
        self.name = name

    def url(self, user: str = "station_a") -> str:
        return self.server.url(user, self.name)

    def admin(self):
        return self.server.admin(self.name)


@pytest.fixture
def pg_database(pg_server, tmp_path, monkeypatch):
    """A fresh archive database (users PG_USERS); each test's station queues in a folder of its own."""
    from psycopg import sql

    from analysis.archive.pg import setup
    from tests.pg_server import ADMIN
    name = f"linpar_t{os.getpid()}_{next(_PG_DATABASES)}"
    pg_server.create_database(name)
    setup(pg_server.url(ADMIN, name), PG_USERS)
    monkeypatch.setenv("LINPAR_QUEUE", str(tmp_path / "queues"))
    db = PgDatabase(pg_server, name)
    yield db
    with pg_server.admin() as conn:
        conn.execute(sql.SQL("DROP DATABASE IF EXISTS {} WITH (FORCE)").format(sql.Identifier(name)))


@pytest.fixture(scope="session")
def qapp(qapp):
    """pytest-qt's application, with the cycle collector in the GUI thread only (app/jobs/gui_gc.py: a worker
    thread that frees a Qt widget deadlocks with the GUI thread)."""
    from app.jobs.gui_gc import collect_in_gui_thread
    collect_in_gui_thread()
    return qapp


def pytest_runtest_teardown(item):
    # Between tests the timer may not have run: collect here, in the main thread, what is due.
    import sys
    gui_gc = sys.modules.get("app.jobs.gui_gc")
    if gui_gc is not None:
        gui_gc.collect_if_due()


# --- make test runs the tests in worker processes (pytest-xdist, --dist loadfile; tests/scheduling.py) ----------

@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    """A test's record_property values as plain Python: xdist sends each report to the controller and cannot
    serialise a numpy scalar (a worker dies with 'can't serialize numpy.float64' and its test is lost)."""
    outcome = yield
    report = outcome.get_result()
    report.user_properties = [(name, _plain(value)) for name, value in report.user_properties]


def _plain(value):
    if hasattr(value, "item") and getattr(value, "ndim", None) == 0:      # a numpy scalar
        return value.item()
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    return value if value is None or isinstance(value, (bool, int, float, str)) else str(value)


@pytest.hookimpl(tryfirst=True)
def pytest_timeout_set_timer(item, settings):
    """pytest-timeout's limits bound a hang, never a speed: written for an idle machine, they are stretched by
    the load when the test starts (a fuzz run of 49 s under a 120 s limit, the large-signal band test of 59 s
    under 300 s: both timed out at load ~12). A hang still ends the test, later on a busy machine."""
    import pytest_timeout

    from tests.pace import load_pace
    return pytest_timeout.pytest_timeout_set_timer(item, settings._replace(timeout=settings.timeout * load_pace()))


def pytest_collection_modifyitems(items):
    from tests.scheduling import rig_file_check
    rig_file_check(items)


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config, log):
    """--dist loadfile with the JACK rig's files as one unit (tests/scheduling.py); any other mode is xdist's."""
    if config.getvalue("dist") != "loadfile":
        return None
    from tests.scheduling import make_scheduler
    return make_scheduler(config, log)


# --- the CLI's outcomes on hostile input (tests/reliability/cli_outcome.py), summed over the workers ----------

_WORKERS_OUTCOMES: Counter = Counter()


def _outcomes_here() -> Counter:
    module = sys.modules.get("tests.reliability.cli_outcome")
    return Counter(module.OUTCOMES) if module else Counter()


def pytest_sessionfinish(session):
    if hasattr(session.config, "workeroutput"):         # an xdist worker: its counts go to the controller
        session.config.workeroutput["cli_outcomes"] = dict(_outcomes_here())


@pytest.hookimpl(optionalhook=True)
def pytest_testnodedown(node, error):
    _WORKERS_OUTCOMES.update(getattr(node, "workeroutput", {}).get("cli_outcomes", {}))


def pytest_terminal_summary(terminalreporter):
    """The fuzz suites' outcome counts, at the end of the run (issues ask for them in their closing notes)."""
    outcomes = _outcomes_here() + _WORKERS_OUTCOMES
    if outcomes:
        counts = ", ".join(f"{n} x {kind}" for kind, n in sorted(outcomes.items()))
        terminalreporter.write_line(f"linpar runs on hostile input: {sum(outcomes.values())} ({counts})")
