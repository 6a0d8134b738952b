"""What the report page shows: each section's anchor, title and status (SHOWN, or why it is
left out). Apart from page.py, so that the sections (sections.py) return a status without
importing the page that calls them."""

from __future__ import annotations

from dataclasses import dataclass

SHOWN = "shown"  # the status of a section on the page; any other is why it is left out


@dataclass(frozen=True)
class Section:
    """One section of the page: its anchor, title, and what it shows ("shown", or the reason it
    does not apply)."""

    key: str
    title: str
    status: str

    @property
    def shown(self) -> bool:
        """The section is on the page (its status is "shown", not a reason it is left out)."""
        return self.status == SHOWN
