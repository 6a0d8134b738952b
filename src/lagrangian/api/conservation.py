"""System methods for what L conserves, Routh's reduction and Hamilton's equations."""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:  # imported by the methods that use them (issue 38)
    from ..analysis.conserved import ConservedQuantities
    from ..analysis.hamilton import Hamiltonian


class ConservationMethods:
    """conserved(), routhian(*cyclic) and hamiltonian() of a System (analysis/conserved.py,
    routh.py, hamilton.py)."""

    def conserved(self) -> ConservedQuantities:
        """The quantities conserved along every motion of the model's own L: each cyclic
        coordinate's momentum p = dL/dq_dot, the Jacobi integral h = q_dot . dL/dq_dot - L (and
        whether it equals T + V), and Noether quantities of affine generators xi = a + B q
        (translations, rotations in Cartesian coordinates); a load or constraint doing virtual
        work along xi breaks one (listed in ``.broken`` with why)."""
        from ..analysis.conserved import conserved_quantities

        found = self.__dict__.get("_conserved")
        if found is None:
            found = self.__dict__["_conserved"] = conserved_quantities(
                self.equations_of_motion())
        return found

    def routhian(self, *cyclic: str):
        """The System reduced by Routh in the coordinates not named: L_R = L - sum p_k q_dot_k
        (the Routhian R = -L_R), each conserved momentum a parameter ``p_<name>`` (its value
        at the model's initial state by default; set it with ``with_parameters``). Steady
        motions become equilibria: ``.equilibria()``, ``.modes()``, ``.simulate()`` work."""
        from ..analysis.routh import routhian_model

        return type(self)(routhian_model(self.equations_of_motion(), list(cyclic)))

    def hamiltonian(self) -> Hamiltonian:
        """H(q, p) = p . q_dot - L with momenta ``p_<q>``; ``.rhs(q, p)`` -> (q_dot, p_dot),
        ``.momenta_of(q, q_dot)``, ``.H`` (written out up to 4 coordinates)."""
        from ..analysis.hamilton import hamiltonian_of

        found = self.__dict__.get("_hamiltonian")
        if found is None:
            found = self.__dict__["_hamiltonian"] = hamiltonian_of(self.equations_of_motion())
        return found
