"""Tables: pandas DataFrames when pandas is installed, else plain column dicts / lists."""

from __future__ import annotations

from typing import Any, Dict, List, Optional

import numpy as np

try:  # pandas is optional
    import pandas as _pd
except ImportError:  # pragma: no cover - exercised only without pandas
    _pd = None


def has_pandas() -> bool:
    return _pd is not None


def require_pandas(what: str):
    if _pd is None:
        raise ImportError(f"{what} needs pandas; install it with `pip install pandas`")
    return _pd


def columns(rows: List[Dict[str, Any]], names: List[str], as_frame: Optional[bool]):
    """A table of `rows` with columns `names`: a DataFrame (pandas, unless as_frame is False),
    else a dict of numpy arrays."""
    use_pd = has_pandas() if as_frame is None else bool(as_frame)
    if use_pd:
        pd = require_pandas("as_frame=True")
        return pd.DataFrame(rows, columns=names)
    out = {}
    for n in names:
        vals = [r.get(n) for r in rows]
        try:
            out[n] = np.asarray(vals)
        except (ValueError, TypeError):  # ragged values
            out[n] = np.asarray(vals, dtype=object)
    return out


def _is_table(v: Any) -> bool:
    return (
        isinstance(v, list)
        and len(v) > 0
        and all(isinstance(r, dict) for r in v)
        and not any(isinstance(x, list) and x and isinstance(x[0], dict) for r in v for x in r.values())
    )


def frames(obj: Any) -> Any:
    """`obj` (parsed results.json) with every list of flat records (a table) as a DataFrame."""
    if isinstance(obj, dict):
        return {k: frames(v) for k, v in obj.items()}
    if _is_table(obj):
        return _pd.DataFrame(obj)
    if isinstance(obj, list):
        return [frames(v) for v in obj]
    return obj
