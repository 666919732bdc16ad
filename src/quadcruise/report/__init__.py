"""Self-contained HTML reports of a flight, a comparison or the paper's reproduction."""

from quadcruise.report.html import (
    comparison_report,
    flight_report,
    html_report,
    markdown_html,
    reproduction_report,
    write_html_report,
)

__all__ = [
    "comparison_report",
    "flight_report",
    "html_report",
    "markdown_html",
    "reproduction_report",
    "write_html_report",
]
