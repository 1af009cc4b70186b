"""What the lint reports: :class:`LintProblem` (one fault, naming the template, the element and
what was expected) and :class:`LintError` (raised with one problem per line)."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class LintProblem:
    """One fault in a rendered URDF.

    ``template`` names the template (or file) the document came from, ``element`` the thing at
    fault (``"link 'forearm'"``, ``"joint 'elbow'"``, ``"robot 'jaco'"``, ``"document"``) and
    ``message`` says what is wrong and what was expected.
    """

    template: str
    element: str
    message: str

    def __str__(self) -> str:
        return f"{self.template}: {self.element}: {self.message}"


class LintError(Exception):
    """Raised by `check_urdf_or_raise` when a document has problems; one problem per line."""

    def __init__(self, problems: list[LintProblem]) -> None:
        self.problems: list[LintProblem] = list(problems)
        super().__init__("\n".join(str(problem) for problem in self.problems))

    def __reduce__(self):  # pickled with its problems, as SpecError: errors cross process boundaries intact
        return (type(self), (self.problems,))
