"""docs/extending.md stays true: each kind's file count is the number of files its table lists, the summary
says the same counts, and every file it names exists (a new one's folder, for NAME)."""
import re

from tests.builders import REPO_ROOT

DOC = REPO_ROOT / "docs" / "extending.md"


def sections() -> list[tuple[int, list[str]]]:
    """(the count a 'Files: N' line states, the files of the table under it), in order."""
    found = []
    for block in re.split(r"^Files: ", DOC.read_text(encoding="utf-8"), flags=re.M)[1:]:
        count, _, rest = block.partition("\n")
        table = re.match(r"\s*(\|.*\n)+", rest).group(0)
        files = re.findall(r"^\| `([^`]+)` \|", table, flags=re.M)
        found.append((int(count), files))
    return found


def test_each_count_is_the_number_of_files_listed_and_the_summary_agrees():
    found = sections()
    assert len(found) == 5
    for count, files in found:
        assert count == len(files), files
    summary = re.findall(r"^\| [a-z' -]+ \| (\d+)", DOC.read_text(encoding="utf-8"), flags=re.M)
    assert [int(n) for n in summary] == [count for count, _ in found]


def test_every_file_named_exists_or_has_its_folder():
    for _, files in sections():
        for name in files:
            path = REPO_ROOT / name
            while "NAME" in path.as_posix():        # a new file: the folder it goes in
                path = path.parent
            assert path.exists(), name
