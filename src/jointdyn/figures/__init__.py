"""Paper figures, one compute + plot pair per figure, registered by name.

Modules in this package register their figures on import; :func:`figure_names`
imports them all.
"""

from ._registry import (FIGURES, Figure, figure_names, make_figure, math_text, pyplot, register_figure, save_figure,
                        use_math_text)

__all__ = ["FIGURES", "Figure", "figure_names", "make_figure", "register_figure", "pyplot", "save_figure", "math_text",
           "use_math_text"]
