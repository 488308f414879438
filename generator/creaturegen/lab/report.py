"""The parity report every parity job writes: gates with measured value, threshold, unit and status."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any


@dataclass
class ParityReport:
    package: str
    gates: list[dict[str, Any]] = field(default_factory=list)
    measurements: dict[str, Any] = field(default_factory=dict)

    def gate(self, name: str, value: float, threshold: float, unit: str, passed: bool | None = None) -> None:
        ok = value <= threshold if passed is None else passed
        self.gates.append(
            {
                "name": name,
                "value": value,
                "threshold": threshold,
                "unit": unit,
                "status": "pass" if ok else "fail",
            }
        )

    @property
    def passed(self) -> bool:
        return all(g["status"] == "pass" for g in self.gates)

    def summary(self) -> str:
        """One line per gate, for error messages and logs."""
        return "\n".join(
            f"{g['status']:4} {g['name']}: {g['value']} (<= {g['threshold']} {g['unit']})" for g in self.gates
        )

    def as_dict(self) -> dict[str, Any]:
        return {
            "package": self.package,
            "status": "pass" if self.passed else "fail",
            "gates": self.gates,
            "measurements": self.measurements,
        }


#: The adapter every parity figure is measured on (DESIGN: Chromium's WebGPU on SwiftShader); a job that
#: ran on another adapter measured something else and must say so by failing.
EXPECTED_ADAPTER = "swiftshader"


def console_problems(lines: list[str]) -> list[str]:
    """Console errors and warnings: r185 logs a failed pipeline with console.error inside an error scope
    and skips the draw, so renderer.onError alone never sees it."""
    return [line for line in lines if line.startswith(("[error]", "[warning]"))]


def adapter_gate(report: ParityReport, adapter: dict[str, object]) -> None:
    text = " ".join(str(v) for v in adapter.values() if v).lower()
    report.gate(
        f"adapter is {EXPECTED_ADAPTER} ({text or 'unknown'})", float(EXPECTED_ADAPTER not in text), 0, ""
    )
