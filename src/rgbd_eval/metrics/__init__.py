"""Scoring: CLEAR MOT with the thesis' extras, gated by image IoU or ground-plane distance.

``evaluate_sequence`` scores one sequence into summable :class:`Counts`;
``summarize(total(...))`` derives every ratio for one or many sequences.
"""

from rgbd_eval.metrics.clear import (
    FrameEvents,
    Match,
    SequenceScores,
    evaluate_sequence,
    score_selections,
)
from rgbd_eval.metrics.counts import COUNTS_SCHEMA, Counts, Summary, summarize, total
from rgbd_eval.metrics.gating import (
    distance_matrix,
    ground_distance_matrix,
    iou_distance_matrix,
    iou_matrix,
    metric_distance_matrix,
)
from rgbd_eval.metrics.hota import HotaCounts

__all__ = [
    "COUNTS_SCHEMA",
    "Counts",
    "FrameEvents",
    "HotaCounts",
    "Match",
    "SequenceScores",
    "Summary",
    "distance_matrix",
    "evaluate_sequence",
    "ground_distance_matrix",
    "iou_distance_matrix",
    "iou_matrix",
    "metric_distance_matrix",
    "score_selections",
    "summarize",
    "total",
]
