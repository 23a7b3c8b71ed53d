"""The contact laws of docs/problems.md P5, written again from the published formulas for the
independent engine (not the kernel's fortran/contact_laws.f90, not martello.oracles).

Within one contact phase a law may switch between branches; the engine locates every
switch as a root of `branch_switch`:
  * `push`: the law's force;
  * `cut`: the clipped laws (kelvin with clipped = true, the Hunt–Crossley family) when
    the formula would pull: F = 0 while δ > 0;
  * `restore`: Jankowski's restoring branch (δ̇ < 0), F = β δ^(3/2)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from .errors import Unsupported

HC_LAWS = ("hunt-crossley", "lankarani-nikravesh", "flores", "gonthier", "hertzdamp")


def kelvin_xi(e):
    """ξ = −ln e/√(π² + ln² e), the unclipped Kelvin law's exact damping ratio; e = 0 is
    critical damping (Anagnostopoulos 1988)."""
    if e <= 0.0:
        return 1.0
    return -math.log(e) / math.sqrt(math.pi ** 2 + math.log(e) ** 2)


def hc_factor(law, e):
    """a = χ v_in from a target e by each law's published formula (docs/problems.md P5)."""
    if law == "hunt-crossley":
        return 1.5 * (1.0 - e)
    if law in ("lankarani-nikravesh", "hertzdamp"):
        return 0.75 * (1.0 - e * e)
    if law == "flores":
        return 8.0 * (1.0 - e) / (5.0 * e)
    if law == "gonthier":
        return (1.0 - e * e) / e
    raise ValueError(law)


def jankowski_xi(e):
    """ξ = (9√5/2)(1 − e²)/(e(e(9π − 16) + 16)) (Jankowski 2005, 2006)."""
    return 4.5 * math.sqrt(5.0) * (1.0 - e * e) / (e * (e * (9.0 * math.pi - 16.0) + 16.0))


@dataclass
class ContactLaw:
    name: str
    terms: list              # the contact's row: [(node index or GROUND, coefficient)]
    gap: float
    scheme: str              # penalty | restitution
    law: str | None
    K: float = 0.0           # stiffness (N/m^n)
    n: float = 1.0           # exponent
    c: float = 0.0           # kelvin: c [N s/m]; jankowski: ξ; HC family: a = χ v_in
    clipped: bool = False
    e: float = 0.0           # restitution scheme: Newton's e
    mstar: float = math.inf

    @property
    def has_cut(self):
        return self.law in HC_LAWS or (self.law == "kelvin" and self.clipped)

    def elastic(self, d):
        """The elastic part K δ^n (the force with δ̇ = 0), continued oddly past δ = 0 so that
        the step that overshoots a separation integrates a smooth law (the root is then
        located on its dense output)."""
        return self.K * math.copysign(abs(d) ** self.n, d)

    def energy(self, d):
        """Recoverable energy K δ^(n+1)/(n + 1) of an active phase (docs/results.md
        "Energy"), the potential of the odd continuation of `elastic`."""
        return self.K * abs(d) ** (self.n + 1.0) / (self.n + 1.0)

    def force(self, d, dd, v_in, branch):
        """The compressive force P of an active phase on its branch (docs/problems.md P5)."""
        if branch == "cut":
            return 0.0
        law = self.law
        el = self.elastic(d)          # odd continuation past δ = 0 (see elastic)
        if law in ("linear", "hertz", "kelvin"):
            return el + self.c * dd
        if law in HC_LAWS:
            chi = self.c / v_in if v_in > 0.0 else 0.0
            return el * (1.0 + chi * dd)
        if law == "jankowski":
            if branch == "restore":
                return el
            cj = 2.0 * self.c * math.sqrt(self.K * math.sqrt(abs(d)) * self.mstar)
            return el + cj * dd
        raise ValueError(law)

    def branch_switch(self, d, dd, v_in, branch):
        """The function whose root ends the branch (None: the branch ends only at δ = 0)
        and the branch that follows it, with the direction of the crossing."""
        if self.law == "kelvin" and self.clipped:
            g = self.K * d + self.c * dd
            return (g, -1.0, "cut") if branch == "push" else (g, 1.0, "push")
        if self.law in HC_LAWS:
            chi = self.c / v_in if v_in > 0.0 else 0.0
            g = 1.0 + chi * dd
            return (g, -1.0, "cut") if branch == "push" else (g, 1.0, "push")
        if self.law == "jankowski":
            return (dd, -1.0, "restore") if branch == "push" else (dd, 1.0, "push")
        return None

    def first_branch(self, dd):
        if self.law == "jankowski" and dd <= 0.0:
            return "restore"
        return "push"


def contact_law(c: dict, terms: list, mstar: float) -> ContactLaw:
    """A [[contact]] table (docs/scene-input.md "[[contact]]") as a ContactLaw: the target
    restitution turned into the law's damping by its published formula."""
    scheme = c["scheme"]
    name, gap = c["name"], float(c.get("gap", 0.0))
    if scheme == "restitution":
        return ContactLaw(name, terms, gap, scheme, None, e=float(c["restitution"]), mstar=mstar)
    if scheme != "penalty":
        raise Unsupported(f"contact {name}: scheme {scheme!r} (penalty and restitution only)")
    law = c.get("law", "linear")
    K = float(c["stiffness"])
    e = c.get("restitution")
    damping = c.get("damping")
    if law in ("linear", "kelvin"):
        n = 1.0
    elif law in ("jankowski", "hertzdamp"):
        n = 1.5
    else:
        n = float(c.get("exponent", 1.5))
    val = 0.0
    if law == "kelvin":
        val = damping if damping is not None else \
            (2.0 * kelvin_xi(e) * math.sqrt(K * mstar) if e is not None else 0.0)
    elif law in HC_LAWS:
        val = damping if damping is not None else (hc_factor(law, e) if e is not None else 0.0)
    elif law == "jankowski":
        val = damping if damping is not None else (jankowski_xi(e) if e is not None else 0.0)
    return ContactLaw(name, terms, gap, scheme, law, K=K, n=n, c=float(val),
                      clipped=bool(c.get("clipped", False)), mstar=mstar)
