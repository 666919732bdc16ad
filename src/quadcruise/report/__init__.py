"""Self-contained HTML reports of a flight, a comparison or the paper's reproduction."""

from quadcruise.report.html import html_report, markdown_html, write_html_report
from quadcruise.report.sections import comparison_report, flight_report, reproduction_report

__all__ = [
    "comparison_report",
    "flight_report",
    "html_report",
    "markdown_html",
    "reproduction_report",
    "write_html_report",
]
