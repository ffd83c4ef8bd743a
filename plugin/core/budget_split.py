"""One memory budget for the whole volume, CPU and GL side together (issue
21), split the way the command-line tool splits --memory-budget
(csrc/cli/cli_stream.c): the volume's CPU side gets half, so that a volume
read whole (at most that half) and its copy on the GL side fit together,
and a streamed volume keeps its index, coarse level and brick cache in that
half while the renderer gets the other half. A volume read whole is freed
once it is on the GL side, so its renderer may use the whole budget.

Plain numbers, no bpy and no library: tests/python/test_streaming_binding.py
checks the sums."""

DEFAULT_BUDGET = 2 << 30  # voxlight.h: a budget of 0 means 2 GiB


def volume_share(total):
    """vxl_load_options.memory_budget_bytes for a total budget (0 = the default)."""
    return (int(total) or DEFAULT_BUDGET) // 2


def renderer_share(total, streamed):
    """vxl_renderer_options.memory_budget_bytes once the volume is open: the
    rest of the budget for a streamed volume, the whole budget (0 stays the
    library's default) for one read whole."""
    if not streamed:
        return int(total)
    return (int(total) or DEFAULT_BUDGET) - volume_share(total)
