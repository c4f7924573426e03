"""Small builders of ground truth and tracker output for the metrics tests."""

from __future__ import annotations

from rgbd_eval.types import Box2D, GroundTruthObject, TrackOutput, TrackStatus, Visibility


def gt(
    object_id: int,
    box: tuple[float, float, float, float] | None = (0.0, 0.0, 10.0, 10.0),
    xy: tuple[float, float] | None = None,
    *,
    frame: int = 0,
    ignore: bool = False,
    visibility: float = 1.0,
) -> GroundTruthObject:
    """A ground-truth object with a box and/or a ground-plane position."""
    return GroundTruthObject(
        frame=frame,
        stamp_ns=frame,
        object_id=object_id,
        box2d=Box2D(*box) if box is not None else None,
        world_xyz=(xy[0], xy[1], 0.9) if xy is not None else None,
        visibility=visibility,
        ignore=ignore,
    )


def track(
    track_id: int,
    box: tuple[float, float, float, float] | None = (0.0, 0.0, 10.0, 10.0),
    xy: tuple[float, float] = (0.0, 0.0),
    *,
    visibility: Visibility = Visibility.VISIBLE,
    status: TrackStatus = TrackStatus.VALIDATED,
) -> TrackOutput:
    """A track output with a box and a ground-plane position."""
    return TrackOutput(
        track_id=track_id,
        x=xy[0],
        y=xy[1],
        height=1.75,
        box2d=Box2D(*box) if box is not None else None,
        visibility=visibility,
        status=status,
    )
