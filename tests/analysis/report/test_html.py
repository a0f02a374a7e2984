"""The HTML report (analysis.report.html): a parameter the data do not determine reads so, with its reason."""
import html

from analysis.report import build_report, render_html
from analysis.report.numbers import NOT_DETERMINED_NOTE


def test_a_parameter_the_data_do_not_determine_reads_so_with_one_line_under_the_table(stored, undetermined_qms):
    page = html.unescape(render_html(build_report(undetermined_qms, {})))
    assert "<td>Qms</td><td class='num'>not determined</td>" in page
    table = page.split("<h2>Parameters</h2>")[1].split("<h2>")[0]
    assert table.count(NOT_DETERMINED_NOTE) == 1 and table.index("</table>") < table.index(NOT_DETERMINED_NOTE)
    assert NOT_DETERMINED_NOTE not in html.unescape(render_html(build_report(stored, {})))
