"""Template rendering and inline images: every page is one self-contained file.

Pages are rendered from the Jinja2 templates shipped in ``rgbd_eval/report/templates``
(autoescaped); images are embedded as ``data:`` URIs (plots as PNG, camera frames
as JPEG, which is a tenth of the size for photographs), so a page opens offline.
"""

from __future__ import annotations

import base64
import functools
import io
from typing import TYPE_CHECKING, Any

import jinja2
import numpy as np
from numpy.typing import NDArray

from rgbd_eval import __version__

if TYPE_CHECKING:
    from matplotlib.figure import Figure

#: JPEG quality of inlined camera frames.
JPEG_QUALITY = 85


@functools.cache
def environment() -> jinja2.Environment:
    """The template environment (templates from the installed package, autoescaped)."""
    env = jinja2.Environment(
        loader=jinja2.PackageLoader("rgbd_eval.report", "templates"),
        autoescape=True,
        undefined=jinja2.StrictUndefined,
        trim_blocks=True,
        lstrip_blocks=True,
    )
    env.globals["tool_version"] = __version__
    return env


def render(template: str, **context: Any) -> str:
    """Render ``templates/<template>`` with ``context``."""
    return environment().get_template(template).render(**context)


def figure_png(fig: Figure) -> bytes:
    """A matplotlib figure as PNG bytes; the figure is closed."""
    import matplotlib.pyplot as plt

    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    plt.close(fig)
    return buf.getvalue()


def data_uri(data: bytes, mime: str = "image/png") -> str:
    """``data`` as a base64 ``data:`` URI."""
    return f"data:{mime};base64," + base64.b64encode(data).decode("ascii")


def jpeg_uri(rgb: NDArray[np.uint8]) -> str:
    """An RGB image (H x W x 3) as a JPEG ``data:`` URI."""
    import cv2

    ok, data = cv2.imencode(
        ".jpg", np.ascontiguousarray(rgb[:, :, ::-1]), [cv2.IMWRITE_JPEG_QUALITY, JPEG_QUALITY]
    )
    if not ok:  # cv2 returns False only for an unusable array (empty, wrong dtype)
        raise ValueError(f"cannot encode an image of shape {rgb.shape} as JPEG")
    return data_uri(data.tobytes(), "image/jpeg")


def pyplot() -> Any:
    """``matplotlib.pyplot`` on the Agg backend (no display needed)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt
