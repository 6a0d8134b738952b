"""What students type, as the model grammar's ASCII: Greek letters by name (θ is theta), dots
above as rates (θ̇ is theta_dot), subscripts, superscripts (² is **2), vulgar fractions (½ is 1/2)
and typographic operators (·, ×, −); the characters refused, with the spelling to use. Tables
only: the expression reader (model/tokens.py) applies them."""

from __future__ import annotations

import unicodedata
from fractions import Fraction

# Greek letters by their ASCII names (theta, Omega); variants and the micro sign as their letter.
GREEK = {chr(0x3B1 + i): name for i, name in enumerate(
    "alpha beta gamma delta epsilon zeta eta theta iota kappa lambda mu nu xi omicron pi rho "
    "sigma sigma tau upsilon phi chi psi omega".split())}
GREEK.update({letter.upper(): name.capitalize() for letter, name in GREEK.items()
               if letter != "\u03c2"})
GREEK.update({"\u03d1": "theta", "\u03d5": "phi", "\u03f5": "epsilon", "\u03f1": "rho",
               "\u03d6": "pi", "\u00b5": "mu"})
SUBSCRIPTS = {chr(0x2080 + d): str(d) for d in range(10)}
SUBSCRIPTS.update({c: f"_{letter}" for c, letter in zip(
    "\u2090\u2091\u2092\u2093\u2095\u2096\u2097\u2098\u2099\u209a\u209b\u209c"
    "\u1d62\u2c7c\u1d63\u1d64\u1d65", "aeoxhklmnpstijruv", strict=True)})
SUPERSCRIPTS = {"\u2070": "0", "\u00b9": "1", "\u00b2": "2", "\u00b3": "3",
                 **{chr(0x2070 + d): str(d) for d in range(4, 10)}, "\u207b": "-", "\u207a": "+"}
FRACTIONS = {c: str(Fraction(unicodedata.numeric(c)).limit_denominator(10))
              for c in "\u00bd\u2153\u2154\u00bc\u00be\u2155\u2156\u2157\u2158\u2159"
                       "\u215a\u2150\u215b\u215c\u215d\u215e\u2151\u2152"}
OPERATORS = dict(zip("\u00b7\u22c5\u2217\u2219\u00d7\u2715\u2212\u2013\u2010\u2012\u00f7\u2215\u2044",
                      "******----///", strict=True))
MARKS = {"\u0307": 1, "\u0308": 2}  # a dot above: the rate (theta_dot); two: theta_ddot
REFUSED = {  # refused, with the ASCII spelling to use instead
    "\u2032": "a prime is not read: write theta_dot for a rate", "\u221e": "infinity is no value",
    "\u2033": "a double prime is not read: write theta_ddot", "\u221a": "write sqrt(...)",
    "\u2202": "write the derivative out", "\u00b0": "write radians (30 degrees is 30*pi/180)"}
