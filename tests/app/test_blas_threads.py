"""app.blas_threads: one BLAS thread unless the user chose (its effect on a whole process:
tests/app/cli/test_analyze_startup.py)."""
from app.blas_threads import VARIABLES, one_blas_thread


def test_all_three_are_set_when_the_user_set_none():
    environ = {"PATH": "/bin", "OMP_NUM_THREADS": ""}
    one_blas_thread(environ)
    assert [environ[name] for name in VARIABLES] == ["1", "1", "1"] and environ["PATH"] == "/bin"


def test_any_one_the_user_set_leaves_all_three_as_they_are():
    for name in VARIABLES:
        environ = {name: "3"}
        one_blas_thread(environ)
        assert environ == {name: "3"}, name
