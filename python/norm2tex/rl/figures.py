"""The hold-the-cube experiment's figures (norm2tex.rl.hold_cube_experiment writes them), drawn
with matplotlib's Agg canvas: PNG files, no display, no pyplot state shared with the caller.

  opening_vs_step.png   opening vs step, a panel per policy, a curve per material (mean and a
                        band of +- one standard deviation over the episodes), each material's
                        drop threshold a dashed line
  training_curves.png   mean training return vs environment steps, a curve per policy
"""

DPI = 100
# Pixel sizes: a margin and 450 px per policy panel by 480 px; the training figure 620 x 420.
OPENINGS_MARGIN_PX, OPENINGS_PANEL_PX, OPENINGS_HEIGHT_PX = 70, 450, 480
TRAINING_SIZE_PX = (620, 420)

PALETTE = {"wood": "#a6611a", "fabric": "#2c7bb6", "smooth": "#4dac26", "empty": "#6e6e6e",
           "rock": "#783c96", "print3d": "#d73027"}
POLICY_COLOURS = {"blind": "#5a5a5a", "textureless": "#2c7bb6", "norm2tex": "#d73027"}
FALLBACK_COLOURS = ("#1b9e77", "#d95f02", "#7570b3", "#e7298a")


def openings_size_px(policies):
    """(width, height) in pixels of opening_vs_step.png for `policies` panels."""
    return (OPENINGS_MARGIN_PX + policies * OPENINGS_PANEL_PX, OPENINGS_HEIGHT_PX)


def plot_openings(path, results, config):
    """Writes openings_figure(results, config) to `path` (PNG)."""
    openings_figure(results, config).savefig(path, format="png")


def plot_training(path, results, config):
    """Writes training_figure(results, config) to `path` (PNG)."""
    training_figure(results, config).savefig(path, format="png")


def openings_figure(results, config):
    """The paper's figure: opening vs step, a panel per policy, a curve per material (mean, and
    a band of +- one standard deviation over the episodes), thresholds dashed; the legend gives
    each material's drop rate. A matplotlib Figure of openings_size_px(policies) pixels."""
    policies = list(results["policies"])
    width, height = openings_size_px(len(policies))
    fig = _figure((width, height))
    axes = fig.subplots(1, len(policies), sharey=True, squeeze=False)[0]
    # Margins in pixels (the tick labels' room does not grow with the panels).
    fig.subplots_adjust(left=60 / width, right=1 - 20 / width, top=1 - 40 / height,
                        bottom=95 / height, wspace=0.15)
    ylim = _openings_ylim(results)
    for ax, policy in zip(axes, policies):
        _openings_panel(ax, policy, results["policies"][policy]["evaluation"],
                        results["thresholds"], config.horizon, ylim)
    axes[0].set_ylabel("opening")
    fig.text(0.01, 0.02, "mean ± std over %d held-out episodes per material; dashed: the "
             "material's drop threshold (largest opening that holds the cube)"
             % config.eval_episodes, fontsize=9)
    return fig


def _openings_ylim(results):
    """At least 0.40-0.75, widened to every mean +- std and threshold."""
    values = [t for t in results["thresholds"].values() if t is not None]
    for entry in results["policies"].values():
        for ev in entry["evaluation"].values():
            for mean, std in zip(ev["opening_mean"], ev["opening_std"]):
                values += [mean - std, mean + std]
    return (min([0.4] + values), max([0.75] + values))


def _openings_panel(ax, policy, evaluation, thresholds, horizon, ylim):
    for i, (material, threshold) in enumerate(thresholds.items()):
        if threshold is not None:
            ax.axhline(threshold, color=_colour(material, PALETTE, i), linestyle="--",
                       linewidth=1)
    for i, (material, ev) in enumerate(evaluation.items()):
        colour = _colour(material, PALETTE, i)
        mean, std = ev["opening_mean"], ev["opening_std"]
        steps = range(len(mean))
        ax.fill_between(steps, [m - s for m, s in zip(mean, std)],
                        [m + s for m, s in zip(mean, std)], color=colour, alpha=0.2, linewidth=0)
        ax.plot(steps, mean, color=colour, linewidth=2,
                label="%s  drop %.0f%%" % (material, 100 * ev["drop_rate"]))
    ax.set_title(policy)
    ax.set_xlabel("step")
    ax.set_xlim(0, horizon)
    ax.set_ylim(*ylim)
    ax.grid(True, axis="y", color="#e8e8e8")
    ax.legend(loc="lower left", fontsize=8)


def training_figure(results, config):
    """Mean training return (episodes finished in each update) vs environment steps, a curve per
    policy. A matplotlib Figure of TRAINING_SIZE_PX pixels."""
    fig = _figure(TRAINING_SIZE_PX)
    ax = fig.subplots()
    fig.subplots_adjust(left=0.13, right=0.95, top=0.9, bottom=0.14)
    for i, (policy, entry) in enumerate(results["policies"].items()):
        points = [(r["steps"], r["mean_return"]) for r in entry["training"]
                  if r.get("mean_return") is not None]
        steps, returns = [s for s, _ in points], [y for _, y in points]
        # One update has one point: a marker, so that it shows without a line.
        ax.plot(steps, returns, color=_colour(policy, POLICY_COLOURS, i), linewidth=2,
                marker="o" if len(points) == 1 else None, label=policy)
    ax.set_title("PPO training: mean episode return")
    ax.set_xlabel("environment steps")
    ax.set_ylabel("return")
    ax.set_xlim(0, max(config.total_steps, 1))
    ax.grid(True, axis="y", color="#e8e8e8")
    ax.legend(loc="upper left", fontsize=8)
    return fig


def _colour(name, table, i):
    return table.get(name, FALLBACK_COLOURS[i % len(FALLBACK_COLOURS)])


def _figure(size_px):
    """A matplotlib Figure of size_px pixels on its own Agg canvas (no pyplot, no display)."""
    try:
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure
    except ImportError as e:
        raise ImportError("the experiment's figures need matplotlib (%s): install it (Debian "
                          "and Ubuntu: apt-get install python3-matplotlib)" % e) from e
    fig = Figure(figsize=(size_px[0] / DPI, size_px[1] / DPI), dpi=DPI)
    FigureCanvasAgg(fig)
    return fig
