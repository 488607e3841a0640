"""A chain of rolls, disambiguated: the paper's rule and the likelihood rule over consecutive
rolls, on splines and on outlines with corners.
"""

from ._disambiguate import RULES, Candidate, Localization, localize
from ._outline_chain import Forward, chain_forward

__all__ = [
    "RULES",
    "Candidate",
    "Localization",
    "localize",
    "Forward",
    "chain_forward",
]
