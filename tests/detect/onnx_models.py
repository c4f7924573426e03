"""Tiny ONNX models built with the ``onnx`` package, for testing the real loading/decoding code."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import onnx
from onnx import TensorProto, helper, numpy_helper


def _save(graph: onnx.GraphProto, path: Path) -> Path:
    model = helper.make_model(graph, opset_imports=[helper.make_opsetid("", 13)])
    model.ir_version = 8
    onnx.checker.check_model(model)
    onnx.save(model, str(path))
    return path


def constant_output_model(
    path: Path,
    input_name: str,
    input_shape: list[int | str],
    input_type: int,
    outputs: dict[str, np.ndarray],
) -> Path:
    """A model whose outputs are fixed arrays plus 0 x (sum of the input): the input is consumed."""
    nodes = [
        helper.make_node("Cast", [input_name], ["as_float"], to=TensorProto.FLOAT),
        helper.make_node("ReduceSum", ["as_float"], ["total"], keepdims=0),
        helper.make_node("Mul", ["total", "zero"], ["nothing"]),
    ]
    inits = [numpy_helper.from_array(np.zeros((), np.float32), "zero")]
    outs = []
    for name, value in outputs.items():
        const = f"{name}_const"
        inits.append(numpy_helper.from_array(value.astype(np.float32), const))
        nodes.append(helper.make_node("Add", [const, "nothing"], [name]))
        outs.append(helper.make_tensor_value_info(name, TensorProto.FLOAT, list(value.shape)))
    graph = helper.make_graph(
        nodes,
        "constant",
        [helper.make_tensor_value_info(input_name, input_type, input_shape)],
        outs,
        initializer=inits,
    )
    return _save(graph, path)


def channel_mean_model(path: Path, height: int, width: int) -> Path:
    """Embedder ``(N, 3, h, w) -> (N, 3)``: the mean of each input channel."""
    node = helper.make_node("ReduceMean", ["x"], ["y"], axes=[2, 3], keepdims=0)
    graph = helper.make_graph(
        [node],
        "channel_mean",
        [helper.make_tensor_value_info("x", TensorProto.FLOAT, ["n", 3, height, width])],
        [helper.make_tensor_value_info("y", TensorProto.FLOAT, ["n", 3])],
    )
    return _save(graph, path)
