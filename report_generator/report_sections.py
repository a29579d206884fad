"""The report's Markdown sections: one table or paragraph per function, from computed results.

The paper's values come from ``report_experiments``; every other number is one the run
measured. ``report_document`` puts the sections in order with the prose around them.
"""

import math
from pathlib import Path

from bench import stiffness_sweep
from bench.teleop_load import verdict
import numpy as np
from report_generator.report_experiments import Experiment, EXPERIMENTS, PAPER, PAPER_TABLE_3
from report_generator.report_format import format_length, format_number, markdown_table
from report_generator.report_image import STREAMS
from report_generator.report_metrics import (angle_stats, angles_to_normal, FALSE_ERROR,
                                             FELT_FORCE, MAX_ANGLE, Measures, SIGN_FLOOR,
                                             STRONG_FORCE)
from report_generator.report_paper_replay import PaperReplay
from report_generator.report_recordings import NO_FORCE_RUN, Recording
from report_generator.report_truth import Truth

from collision_engine import read_scene
from collision_engine.mesh_io import load_mesh
from haptic_bringup.contacts import contact_intervals, MIN_FORCE

__all__ = ['DEFINITIONS', 'counts_section', 'error_time_section', 'experiment_section',
           'extreme_section', 'force_effect_section', 'gateway_session_section',
           'headline_section', 'identical_modes', 'interval_table', 'link_section',
           'loop_section', 'provenance_section', 'servo_section',
           'stiff_wall_section', 'sweep_section', 'table_2', 'table_3', 'teleop_load_section',
           'teleop_section', 'tradeoff_section']


def provenance_section(info: dict, recordings: dict, argv: list) -> str:
    """Say how, when, on what and from which bags the report was made."""
    versions = ', '.join(f'{k} {v}' for k, v in info['versions'].items())
    bags = ', '.join(f'{n} {r.recorded_at}' for n, r in recordings.items())
    return '\n'.join([
        f'- **Made** {info["date"]} by `python report_generator/report.py {" ".join(argv)}`, '
        f'commit `{info["commit"]}`',
        f'- **Machine** {info["cpu"]}, {info["cores"]} cores, {info["platform"]}; Python '
        f'{info["python"]}; load average {" / ".join(f"{v:.1f}" for v in info["load"])}',
        f'- **Versions** {versions}',
        f'- **Bags** (demo over ROS 2, recorded) {bags}',
    ])


def headline_section(recordings: dict, results: dict) -> str:
    """Tabulate errors, false values and force directions per experiment, ours and the paper's."""
    header = ['experiment', 'samples', 'mean abs. error: ours', 'paper\'s method on our path',
              'paper (reported)', 'max abs. error: ours', 'paper\'s method on our path',
              'false values (events): ours', 'paper\'s method', 'paper (reported)',
              'force direction error, mean / max: ours', 'paper\'s law on the same contacts']
    rows = []
    for name, m in results.items():
        ours_angle, paper_angle = angle_stats(m.ours_angles), angle_stats(m.paper_angles)
        rows.append([
            name, len(recordings[name].session.time), format_length(m.ours['mean']),
            format_length(m.paper['mean']), format_length(PAPER[name].mean_error),
            format_length(m.ours['max']), format_length(m.paper['max']), m.ours_events[0],
            m.paper_events[0], PAPER[name].false_values,
            f'{format_number(ours_angle[0])}° / {format_number(ours_angle[1])}°',
            f'{format_number(paper_angle[0])}° / {format_number(paper_angle[1])}°'])
    return markdown_table(header, rows)


DEFINITIONS = f"""\
How to read it:

- **Error** is the answer minus the exact signed distance at the same tip position (negative
  inside), over every answered pose of the 10 s run. *Ours* is what the collision engine
  published during the run, read from the bag. *The paper's method* is the paper's own MATLAB
  collision code, re-implemented line by line (`report_generator/paper_method.py`), run on the
  same tip positions against the paper's STL object placed as ours: its distance is unsigned,
  so it is signed here by its own collision flag (negative when the flag is set), the reading most
  favourable to it. *Paper (reported)* is the number printed in the paper, for its own runs;
  for the cylinder and the cuboid its text gives that average over its miscalculated instants
  only, so it compares with a *max* here more than with a mean.
- A **false value** is a sample with no answer, an error above {FALSE_ERROR * 1e3:g} mm, or the
  wrong sign (where the truth is more than {SIGN_FLOOR:g} m from the surface); consecutive false
  samples count as one event.
- **Force direction error** is the angle between the force and the exact outward normal at the
  tip, over the samples where the tip is truly inside and the force is at least
  {FELT_FORCE * 1e3:g} mN (1-2 % of a tap's peak). Weaker forces are the damper's residue in
  the last millisecond of a contact, where our unilateral clip leaves only a tangential
  millinewton (90°) and the paper's law pulls inward (180°); each experiment's section also
  gives the maximum over every force above {MIN_FORCE:g} N.
  *Ours* is the recorded wrench (our spring-damper along the normal, passivity and saturation
  on). *The paper's law* is F = (r/|r|) k dist - kd v with r = tip - centroid of the STL's
  vertex rows, its distance and flag from its code, v the recorded twist.
- The exact truth: analytic for the box and the cylinder, brute force over every triangle with
  a winding-number sign for the hand (`ground_truth/distances.py`, no code shared with the
  engine)."""


def _worst(angles: np.ndarray, time: np.ndarray, force: np.ndarray) -> str:
    """Say when the largest angle happened and how strong that force was."""
    if not np.isfinite(angles).any():
        return 'no force in contact'
    k = int(np.nanargmax(angles))
    return f'at t = {time[k]:.3f} s, |F| = {1e3 * np.linalg.norm(force[k]):.3g} mN'


def experiment_section(recording: Recording, replay: PaperReplay, m: Measures,
                       figure: str) -> str:
    """Describe one experiment under its figure: contacts, errors, force directions, loop."""
    name = recording.experiment.name
    paper = PAPER[name]
    ours_angle, paper_angle = angle_stats(m.ours_angles), angle_stats(m.paper_angles)
    loop = recording.loop
    lines = [
        f'### {name}: {recording.experiment.description} (the paper\'s Figure {paper.figure})',
        '', f'![{name}]({figure})', '',
        f'- {len(recording.session.time)} answered poses in {recording.session.time[-1]:.2f} s; '
        f'{m.truth_contacts} contacts by the exact truth, {len(recording.contacts)} by our '
        f'engine, {m.paper_contacts} by the paper\'s collision flag on the same path (the paper '
        f'reports {paper.collisions}).',
        f'- Distance error, ours: mean {format_length(m.ours["mean"])}, max '
        f'{format_length(m.ours["max"])}; false values {m.ours_events[0]} events '
        f'({m.ours_events[1]} samples).',
        f'- The paper\'s method on the same path: mean {format_length(m.paper["mean"])}, max '
        f'{format_length(m.paper["max"])}; false values {m.paper_events[0]} events '
        f'({m.paper_events[1]} samples); its flag missed {m.paper_missed} samples inside and '
        f'was set on {m.paper_false_flags} outside; its distance search converged on '
        f'{m.outcomes["converged"]}, gave up at the cap (returning its last, not its best, '
        f'triangle) on {m.outcomes["cap"]}, and would never finish in MATLAB on '
        f'{m.outcomes["hang"]} samples. The paper reports a mean error of '
        f'{format_length(paper.mean_error)} ({paper.error_source}) and {paper.false_values} '
        'false values.',
        f'- Force direction error in contact (forces of {FELT_FORCE * 1e3:g} mN or more): ours '
        f'mean {format_number(ours_angle[0])}°, max {format_number(ours_angle[1])}° '
        f'({_worst(m.ours_angles, recording.session.time, recording.session.applied)}); the '
        f'paper\'s law mean {format_number(paper_angle[0])}°, max '
        f'{format_number(paper_angle[1])}° '
        f'({_worst(m.paper_angles, recording.session.time, replay.force)}). Over every force '
        f'above {MIN_FORCE:g} N the maxima are '
        f'{format_number(angle_stats(m.ours_all_angles)[1])}° (ours) and '
        f'{format_number(angle_stats(m.paper_all_angles)[1])}° (the paper\'s law).',
        _strong_line(m.strong_angles),
    ]
    if loop:
        lines.append(
            f'- Loop during this run: {float(loop["rate_hz"]):.0f} Hz poses, '
            f'{float(loop["answered_percent"]):.1f} % answered, round trip p50 '
            f'{1e3 * float(loop["latency_p50_s"]):.2f} ms, p99 '
            f'{1e3 * float(loop["latency_p99_s"]):.2f} ms, max '
            f'{1e3 * float(loop["latency_max_s"]):.2f} ms.')
    if not recording.scene_matches:
        lines.append('- **The bag\'s scene differs from the shipped scene file**: the truth '
                     'uses the shipped one.')
    return '\n'.join(lines)


def interval_table(recording: Recording, truth: Truth, replay: PaperReplay) -> str:
    """Per contact interval: our mean force and direction error, the paper's law, the paper's."""
    session, paper = recording.session, PAPER[recording.experiment.name]
    header = ['#', 'ours: interval s', 'Fx N', 'Fy N', 'Fz N', '∠ normal °',
              'paper\'s law, same samples: Fx', 'Fy', 'Fz', '∠ normal °']
    if paper.intervals:
        header += [f'paper ({paper.table}): interval s', 'Fx', 'Fy', 'Fz']
    rows = []
    count = max(len(recording.contacts), len(paper.intervals))
    for k in range(count):
        row = [k + 1]
        if k < len(recording.contacts):
            c = recording.contacts[k]
            window = (session.time >= c.start) & (session.time <= c.end)
            ours = angles_to_normal(session.applied[window], truth.normal[window],
                                    min_force=FELT_FORCE)
            law = angles_to_normal(replay.force[window], truth.normal[window],
                                   min_force=FELT_FORCE)
            row += [f'{c.start:.2f}–{c.end:.2f}', *(format_number(f) for f in c.mean_force),
                    format_number(np.nanmean(ours) if np.isfinite(ours).any() else math.nan),
                    *(format_number(f) for f in np.nanmean(replay.force[window], axis=0)),
                    format_number(np.nanmean(law) if np.isfinite(law).any() else math.nan)]
        else:
            row += [''] * 9
        if paper.intervals:
            row += ([f'{paper.intervals[k][0]:g}–{paper.intervals[k][1]:g}',
                     *(f'{f:g}' for f in paper.intervals[k][2:])]
                    if k < len(paper.intervals) else [''] * 4)
        rows.append(row)
    inside = truth.distance < 0.0
    mean_abs = np.nanmean(np.abs(session.applied[inside]), axis=0)
    law_abs = np.nanmean(np.abs(replay.force[inside]), axis=0)
    rows.append(['all', 'mean \\|F\\| in contact', *(format_number(f) for f in mean_abs), '',
                 *(format_number(f) for f in law_abs), ''] + (
        ['paper, as reported', *(f'{f:g}' for f in paper.mean_force)]
        if paper.intervals else []))
    table = markdown_table(header, rows)
    if not paper.intervals:
        table += (f'\n\nThe paper gives no interval table here; its mean contact forces were '
                  f'{", ".join(f"{f:g}" for f in paper.mean_force)} N (x, y, z).')
    return table


def table_2(results: dict, replays: dict) -> str:
    header = ['object', 'vertices: paper', 'ours', 'paper\'s method (rows)',
              'mean abs. error: paper (reported)', 'paper\'s method on our path', 'ours',
              'false values: paper', 'paper\'s method', 'ours',
              'collisions: paper', 'paper\'s flag on our path', 'exact truth on our path']
    rows = []
    for name, m in results.items():
        paper = PAPER[name]
        rows.append([name, paper.vertices, _exact_geometry(EXPERIMENTS[name]),
                     len(replays[name].rows), format_length(paper.mean_error),
                     format_length(m.paper['mean']), format_length(m.ours['mean']),
                     paper.false_values, m.paper_events[0], m.ours_events[0], paper.collisions,
                     m.paper_contacts, m.truth_contacts])
    return markdown_table(header, rows)


def _exact_geometry(experiment: Experiment) -> str:
    """Describe the object our engine queried: a primitive, or a mesh's welded vertices."""
    shape = read_scene(experiment.scene_file).objects[0].shape
    if not hasattr(shape, 'file'):
        return f'exact {type(shape).__name__.removesuffix("Spec").lower()} primitive'
    mesh = load_mesh(shape.file, scale=shape.scale, check_self_intersection=False)
    return f'exact mesh, {len(mesh.vertices)} vertices'


def table_3(recording: Recording) -> str:
    """Set the paper's hand check of one instant beside the same check of our deepest push."""
    session = recording.session
    k = int(np.argmin(session.distance))
    material = read_scene(recording.experiment.scene_file).objects[0]
    stiffness, damping = material.material.stiffness, material.material.damping
    velocity = recording.velocity[k]
    vector = session.point[k] - session.tip[k]
    law = stiffness * vector - damping * velocity
    header = ['', 'paper: t = 8.436 s: v m/s', 'distance vector m', 'F N',
              f'ours: t = {session.time[k]:.3f} s: v m/s', 'x = point - tip m',
              'K x - C v N', 'F published N']
    rows = [[axis, *(format_number(value, 4) for value in (
        PAPER_TABLE_3['velocity'][i], PAPER_TABLE_3['distance_vector'][i],
        PAPER_TABLE_3['force'][i], velocity[i], vector[i], law[i], session.applied[k, i]))]
        for i, axis in enumerate('XYZ')]
    return markdown_table(header, rows)


def error_time_section(rows: list[dict]) -> str:
    """Tabulate time and error per object and method; a method that could not run says why."""
    header = ['object', 'method', 'geometry', 'n', 'median us', 'p99 us', 'mean abs. error m',
              'max abs. error m', 'sign errors']
    table = []
    for r in rows:
        if 'unavailable' in r:
            table.append([r['object'], r['method'], r['geometry'], '-', '-', '-', '-', '-',
                          f'not run: {r["unavailable"]}'])
            continue
        table.append([r['object'], r['method'], r['geometry'], r['n'],
                      *(format_number(r[key]) for key in ('median_us', 'p99_us', 'mean', 'max')),
                      r['sign_errors']])
    return markdown_table(header, table)


def tradeoff_section(rows: list[dict]) -> str:
    """Tabulate our GJK's time, iterations and error per tolerance and iteration cap."""
    header = ['shape', 'sweep', 'value', 'median us', 'p99 us', 'mean iterations',
              'not converged', 'mean abs. error m', 'max abs. error m']
    return markdown_table(header, [
        [r['shape'], r['sweep'], f'{r["value"]:g}', format_number(r['median_us']),
         format_number(r['p99_us']), format_number(r['iterations']),
         f'{r["not_converged"]}/{r["n"]}', format_number(r['mean']), format_number(r['max'])]
        for r in rows])


def loop_section(comparisons: list[dict]) -> str:
    """Tabulate the loop against its floor: ratios, the loop's own figures, the targets."""
    from bench import bench_loop

    table = []
    for c in comparisons:
        loop, floor, ratios = c['median']['loop'], c['median']['floor'], c['ratios']
        held = all(ok for _, ok in bench_loop.verdicts(c))
        table.append([c['layout'], 'on' if c['recorder'] else 'off',
                      f'{loop["cpu"]:.0f} / {floor["cpu"]:.0f} = {ratios["cpu"]:.2f}',
                      f'{loop["rate"]:.0f} / {floor["rate"]:.0f} = {ratios["rate"]:.3f}',
                      f'{loop["answered"]:.2f} / {floor["answered"]:.2f}',
                      f'{1e3 * loop["p50"]:.2f} / {1e3 * floor["p50"]:.2f} = '
                      f'{ratios["p50"]:.2f}',
                      f'{1e3 * loop["p99"]:.2f} / {1e3 * floor["p99"]:.2f} = '
                      f'{ratios["p99"]:.2f}',
                      'held' if held else 'missed: ' + '; '.join(
                          what for what, ok in bench_loop.verdicts(c) if not ok)])
    return markdown_table(['layout', 'recorder', 'CPU % loop / floor', 'pose Hz loop / floor',
                           'answered % loop / floor', 'p50 ms loop / floor',
                           'p99 ms loop / floor', 'targets'], table)


def sweep_section(rows: list) -> str:
    """Tabulate the stiffness sweep: energy, oscillation, force and depth per K and mode."""
    header = ['K N/m', 'passivity', 'energy generated J', 'early p-p mm', 'late p-p mm',
              'late/early', 'max F N', 'max penetration mm']
    return markdown_table(header, [
        [f'{r.stiffness:.0f}', r.mode, f'{r.generated_energy:+.3e}',
         format_number(1e3 * r.early_amplitude), format_number(1e3 * r.late_amplitude),
         format_number(r.decay_ratio), format_number(r.max_force),
         format_number(1e3 * r.max_penetration)] for r in rows])


def identical_modes(rows: list) -> str:
    """Say at how many stiffnesses two passivity modes gave exactly the same numbers."""
    def numbers(r):
        return (r.generated_energy, r.early_amplitude, r.late_amplitude, r.max_force,
                r.max_penetration)

    by_key = {(r.mode, r.stiffness): numbers(r) for r in rows}
    stiffnesses = sorted({r.stiffness for r in rows})
    modes = stiffness_sweep.MODES
    notes = []
    for k, a in enumerate(modes):
        for b in modes[k + 1:]:
            same = sum(by_key.get((a, s)) == by_key.get((b, s)) for s in stiffnesses)
            if same:
                notes.append(f'`{a}` and `{b}` give exactly the same numbers at {same} of '
                             f'{len(stiffnesses)} stiffnesses.')
    return ' '.join(notes)


def extreme_section(rows: list) -> str:
    """Tabulate the extreme-geometry cases: error, iterations, statuses, agreement with FCL."""
    header = ['case', 'size m', 'points', 'max abs. error m', 'error / size', 'max iterations',
              'statuses', 'FCL: max \\|ours - FCL\\| m', 'FCL disagreements', 'outcome']
    return markdown_table(header, [
        [r.case, format_number(r.scale, 2), r.points, format_number(r.max_error, 2),
         format_number(r.max_relative_error, 2), r.max_iterations, r.statuses,
         format_number(r.fcl_max_discrepancy, 2), r.fcl_disagreements, r.outcome]
        for r in rows])


def counts_section(recordings: dict) -> str:
    """Tabulate messages published and recorded per topic and experiment."""
    topics = sorted({t for r in recordings.values() for t in r.counts})
    header = ['topic', *(f'{n}: published / recorded' for n in recordings)]
    rows = [[t, *(' / '.join(str(v) if v is not None else '?'
                             for v in r.counts.get(t, (None, None)))
                  for r in recordings.values())] for t in topics]
    return markdown_table(header, rows)


def _strong_line(angles: np.ndarray) -> str:
    """Whether every applied force of STRONG_FORCE or more points within MAX_ANGLE."""
    strong = angles[np.isfinite(angles)]
    worst = float(strong.max()) if strong.size else math.nan
    verdict = 'held' if strong.size and worst <= MAX_ANGLE else 'MISSED'
    return (f'- Every applied force of {STRONG_FORCE * 1e3:g} mN or more ({strong.size} ticks) '
            f'within {MAX_ANGLE:g}° of the exact outward normal: the largest angle is '
            f'{format_number(worst)}° ({verdict}).')


def servo_section(rows: list) -> str:
    """Tabulate the servo rate's cost, the stiffest clean wall and the felt latency.

    The contacts are keyed by stiffness, N/m (as text, read back from a stored run).
    """
    stiffnesses = [float(k) for k in rows[0]['local_contacts']]
    return markdown_table(
        ['servo rate (Hz)', 'period p50 (µs)', 'period p99 (µs)', 'stiffest clean wall (N/m)',
         'felt (ms)', 'contacts per tap, local / remote, at K = '
         + ', '.join(f'{k:g}' for k in stiffnesses), 'felt, remote (ms)'],
        [[f'{r["rate"]:.0f}', f'{r["cost_p50_us"]:.1f}', f'{r["cost_p99_us"]:.1f}',
          f'{r["stiffest_clean"]:g}', f'{r["latency_ms"]:.3f}',
          ' '.join(str(c) for c in r['local_contacts'].values()) + ' / '
          + ' '.join(str(c) for c in r['remote_contacts'].values()),
          f'{r["remote_latency_ms"]:.2f}'] for r in rows])


def stiff_wall_section(rows: list) -> str:
    """Tabulate rebounds, work, depth and force of the stiff wall over the loop."""
    return markdown_table(
        ['K N/m', 'layout', 'rendering', 'contacts per tap', 'net work on the tip (mJ)',
         'deepest (mm)', 'deepest / continuous wall', 'peak applied force (N)',
         'poses answered'],
        [[f'{r["stiffness"]:.0f}', r['layout'], r['rendering'],
          f'{r["contacts_per_tap"]:.1f}', f'{1e3 * r["net_work_j"]:+.2f}',
          f'{1e3 * r["max_depth_m"]:.2f}', f'{r["max_depth_m"] / r["ideal_depth_m"]:.2f}',
          f'{r["peak_force_n"]:.2f}', f'{r["answered_percent"]:.2f} %'] for r in rows])


def force_effect_section(cuboid: Recording, without: list | None, demo_dir: Path) -> str:
    """Put the cuboid taps with the force and without it (the demo's control run) side by side.

    ``without`` is the control run's contact intervals, None when the demo in ``demo_dir``
    made no control run.
    """
    if without is None:
        return f'*The demo\'s control run ({NO_FORCE_RUN}) was not found in {demo_dir}.*'
    with_force = contact_intervals(cuboid.session)
    rows = [[label, len(contacts), format_number(1e3 * max(c.max_depth for c in contacts)),
             format_number(1e3 * float(np.median([c.max_depth for c in contacts])))]
            for label, contacts in (('rendered force', with_force),
                                    ('force held at zero (control)', without))]
    return ('The same scripted hand taps the cuboid twice: once with the rendered force, once '
            'with it held at zero. The hand aims 10 mm inside the face; the force stops it a '
            'few millimetres in.\n\n' + markdown_table(
                ['cuboid taps', 'contacts', 'deepest (mm)', 'median deepest per tap (mm)'], rows))


def teleop_section(rows: list) -> str:
    """Tabulate each scheme's stability, transparency, patient force, tracking, smoothness."""
    def number(value: float, fmt: str) -> str:
        return '–' if not np.isfinite(value) else format(value, fmt)
    return markdown_table(
        ['scheme', 'one-way delay (ms)', 'run', 'stable', 'net work on the hand (mJ)',
         'oscillation (%)', 'transparency error (N)', '(% of mean contact force)',
         'peak patient force (N)', 'tracking RMS (mm)', 'felt step ratio p99', '(max)',
         'jumps > 1 N', 'time to force (s)', 'peak rise (N/s)', 'sweep force error max (N)',
         '(RMS)'],
        [[r['scheme'], f'{1e3 * r["delay"]:g}',
          ', '.join(filter(None, (r['source'], r.get('site_streams', '')))),
          'yes' if r['stable'] else '**no**',
          f'{1e3 * r["net_work_j"]:+.1f}', f'{r["oscillation_percent"]:.1f}',
          number(r['transparency_n'], '.2f'), number(r['transparency_percent'], '.1f'),
          f'{r["peak_patient_n"]:.2f}', f'{1e3 * r["tracking_m"]:.1f}',
          number(r.get('step_ratio_p99', np.nan), '.1f'),
          number(r.get('step_ratio_max', np.nan), '.1f'), str(r.get('jumps', '–')),
          number(r.get('time_to_force_s', np.nan), '.2f'),
          number(r.get('peak_rise_n_per_s', np.nan), '.0f'),
          number(r.get('hold_error_max_n', np.nan), '.2f'),
          number(r.get('hold_error_rms_n', np.nan), '.2f')]
         for r in rows])


def teleop_load_section(rows: list) -> str:
    """Tabulate the scan quiet and with cores hogged, the fix beside the code before it."""
    return markdown_table(
        ['scheme', 'load', 'code', 'poses (Hz)', 'poses > 10 ms late', 'longest gap (ms)',
         'remote site (Hz)', 'link silences', 'stable', 'in contact (s)',
         'net work on the hand (mJ)', 'oscillation (%)', 'load average'],
        [[r['scheme'], r['load'], r['code'], f'{r["rate_hz"]:.0f}', str(r['late_poses']),
          f'{1e3 * r["longest_gap_s"]:.0f}', f'{r["remote_rate_hz"]:.0f}', str(r['silences']),
          {'yes': 'yes', 'NO': '**no**'}.get(verdict(r), verdict(r)), f'{r["contact_s"]:.1f}',
          f'{1e3 * r["net_work_j"]:+.1f}', f'{r["oscillation_percent"]:.1f}',
          f'{r["load_before"]:.1f}'] for r in rows])


def gateway_session_section(stored: dict) -> str:
    """Tabulate the scan's streams and CPU with the gateways in the sites' processes and apart."""
    summary = stored['summary']
    rows = [[label, f'{summary["ratios"][key]:.3f}',
             '{:.3f}-{:.3f}'.format(*summary['ranges'][key])]
            for key, (label, _) in STREAMS.items()]
    cpu = '; '.join(f'gateways {layout}: {values["total"]:.0f} % in all (operator\'s site '
                    f'{values["operator"]:.0f} %, remote site {values["remote"]:.0f} %)'
                    for layout, values in summary['cpu_percent'].items())
    return (markdown_table(['figure', 'in the sites / apart (median)', 'range'], rows)
            + f'\n\n{summary["pairs"]} alternated pairs. CPU of the session\'s processes, in % '
            f'of one core (medians): {cpu}.')


def link_section(stored: dict) -> str:
    """Tabulate the round trip over UDP, Zenoh alone and both gateway layouts, loss and CPU."""
    from bench import bench_link

    def median(case: str, key: str) -> float:
        return float(np.median([run[key] for run in stored['runs'][case]]))
    summary = stored['summary']
    quantiles = ('p50', 'p99', 'p99.9')
    paths = {'floor': 'plain UDP (the floor)',
             'floor_in_tick': 'plain UDP between ends that take it in 1 ms ticks (the floor in '
                              'ticks)',
             'zenoh': 'Zenoh alone, between the end processes',
             'gateways': 'the gateways as processes of their own (the baseline)',
             'in_process': "the gateways in the sites' processes, taken in the ends' ticks "
                           '(deployed)'}
    added_by = [('Zenoh alone', summary['zenoh']),
                ('the gateway processes', summary['gateways']),
                ("the gateways in the sites' processes", summary['in_process']),
                ("the gateways in the sites' processes, over the floor in ticks",
                 summary['over_floor_in_tick']['in_process'])]
    rows = [[paths[case], *(f'{median(case, f"{q}_ms"):.3f}' for q in quantiles),
             f'{sum(r["lost"] for r in stored["runs"][case])} of '
             f'{sum(r["sent"] for r in stored["runs"][case])}'] for case in paths]
    for what, over in added_by:
        added = (f'{over["added_ms"][q]:+.3f} ({over["ratio"][q]:.1f} ×)' for q in quantiles)
        rows.append([f'added by {what}', *added, ''])
    cpu = ', '.join(f'{name} {value:.1f} %' for name, value in summary['gateway_cpu_pct'].items())
    echo = ', '.join(f'{value:.1f} % ({case})' for case, value in summary['echo_cpu_pct'].items())
    in_site = '; '.join(
        f'{role} ' + ', '.join(f'{value:.1f} % ({case})' for case, value in summary[key].items())
        for role, key in (('remote', 'in_process_gateway_cpu_pct'),
                          ('operator', 'operator_in_process_gateway_cpu_pct')))
    return (markdown_table(['path', 'round trip p50 (ms)', 'p99 (ms)', 'p99.9 (ms)', 'lost'],
                           rows)
            + f'\n\nCPU over the window, in % of one core: {cpu}; the echo {echo}. Each gateway '
            f'in its site\'s process, over the same site ticking without it (the remote one: the '
            f'ticking echo alone, in the same window; the operator\'s: the ping end in the floor '
            f'in ticks, in the same round): {in_site}.\n\nTargets of the deployed path '
            f'(issue 27): ' + '; '.join(f'{what}: {"held" if holds else "**missed**"}'
                                        for what, holds in bench_link.verdicts(summary)) + '.')
