// The Job panel while a job runs (issue 33): which program the machine runs, block and line, an
// ETA, a depth bar (the hole's depth against its programmed depth), the running line highlighted
// in the editor — only when the editor holds the very text the machine runs — and the feed
// override as the machine has it. Everything comes from what the page already receives: status
// (`job` and the `*.job_*` variables), the server's job snapshot (`drills`, `dry_run`) and the
// chart rows (`depth_est`, `override`).
import { units } from './prefs.js';

const $ = (id) => document.getElementById(id);

function statusVar(s, suffix) {
  const v = s?.vars || {};
  for (const k of Object.keys(v)) if (k === suffix || k.endsWith(`.${suffix}`)) return v[k];
  return undefined;
}

const num = (v) => typeof v === 'number' && Number.isFinite(v);

/** m:ss (h:mm:ss from an hour). */
export function clock(s) {
  if (!num(s) || s < 0) return '—';
  const t = Math.round(s);
  const h = Math.floor(t / 3600); const m = Math.floor((t % 3600) / 60); const sec = t % 60;
  const mm = h ? String(m).padStart(2, '0') : String(m);
  return `${h ? `${h}:` : ''}${mm}:${String(sec).padStart(2, '0')}`;
}

/**
 * Whose program the status' job is: 'none' (no job since edmplc started), 'mdi' (an MDI line),
 * 'page' (the program this server uploaded: the snapshot's generation), 'earlier' (a program
 * committed before the page's last upload: the machine now holds the page's), or 'elsewhere'
 * (committed after it, by someone else: generations only grow).
 */
export function jobOwner(status, job) {
  const j = status?.job;
  if (!j || j.outcome === 'none') return 'none';
  if (j.slot === 'mdi') return 'mdi';
  const mine = job && job.blocks > 0 ? job.generation : null;
  if (mine !== null && j.generation === mine) return 'page';
  if (mine !== null && j.generation < mine) return 'earlier';
  return 'elsewhere';
}

/**
 * Remaining time of a running job, in s of machine time, and what it is estimated from: the
 * drilling rate so far when the program drills (total programmed depth against depth done),
 * else the blocks done so far. null when there is nothing to go on yet.
 */
export function estimate({ elapsed, block, blocks, drills, depthNow }) {
  if (!num(elapsed) || elapsed <= 0) return null;
  if (drills && drills.length) {
    let total = 0; let done = 0;
    for (const [b, , depth] of drills) {
      total += depth;
      if (b < block) done += depth;
      else if (b === block && num(depthNow)) done += Math.min(Math.max(depthNow, 0), depth);
    }
    if (total > 0 && done > 0.02 * total) return { left: (total - done) * elapsed / done, from: 'the drilling rate so far' };
  }
  if (blocks > 0 && block > 0) return { left: elapsed * (blocks - block) / block, from: 'the blocks done so far' };
  return null;
}

/** The drilling block the depth bar shows: the one running, else the last one begun. */
function drillFor(drills, block) {
  let at = null;
  for (const d of drills || []) if (d[0] <= block) at = d;
  return at ?? (drills?.[0] || null);
}

export class JobPanel {
  constructor(editor, toolpath) {
    this.editor = editor;
    this.toolpath = toolpath;
    this.owner = 'none';
    this.pathShown = true;
  }

  /** status: the last status event; job: the server's snapshot; latest: the chart rows' last values. */
  update(status, job, latest) {
    const j = status?.job || {};
    const owner = jobOwner(status, job);
    this.owner = owner;
    const running = j.outcome === 'running';
    const ours = owner === 'page';
    const dry = ours && !!job?.dry_run;
    $('job-dry').hidden = !dry;
    $('job-foreign').hidden = owner !== 'elsewhere';
    document.body.dataset.jobOwner = owner;

    let part = job?.part || 'none';
    let note = '';
    if (owner === 'elsewhere') {
      part = `a program loaded elsewhere (generation ${j.generation}, ${j.blocks} blocks)`;
      const mine = job?.blocks ? `${job.part || 'the page\u2019s program'} (generation ${job.generation})` : 'nothing';
      note = `${running ? 'Running' : 'The last job ran'} a program loaded elsewhere (program generation ${j.generation}, ${j.blocks} blocks, e.g. by edmhmi run), not what this page uploaded: ${mine}. Its text is not known here: no line is highlighted and the toolpath is not shown. Upload before Start.`;
    } else if (owner === 'mdi') {
      part = `MDI line${job?.part ? ` (loaded: ${job.part})` : ''}`;
    } else if (ours && running && this.editor.text !== job.text) {
      note = `The editor holds an edited copy: the machine runs line ${j.line} of ${job.part} as uploaded (not highlighted).`;
    }
    $('job-part').textContent = part;
    $('job-note').textContent = note;

    // The running line, only in the very text the machine runs.
    const same = ours && this.editor.text === job.text;
    this.editor.setCurrent(same && running ? j.line || 0 : 0);
    // The page's toolpath is not the path of a program loaded elsewhere.
    const showPath = owner !== 'elsewhere';
    if (showPath !== this.pathShown) {
      this.pathShown = showPath;
      this.toolpath.setPath(showPath ? job?.toolpath || [] : []);
    }

    const elapsed = statusVar(status, 'job_time_s');
    const drills = ours ? job?.drills : null;
    const depthNow = num(latest?.depth_est) ? latest.depth_est : statusVar(status, 'job_depth_mm');
    if (running) {
      const e = estimate({ elapsed, block: j.block, blocks: j.blocks, drills, depthNow });
      $('job-eta').textContent = e ? `≈ ${clock(e.left)} left (${e.from})` : 'estimating…';
      $('job-eta').dataset.left = e ? String(e.left) : '';
    } else {
      $('job-eta').textContent = j.outcome === 'finished' ? 'done' : '—';
      $('job-eta').dataset.left = '';
    }
    this.showDepth(j, drills, depthNow, dry, owner, statusVar(status, 'job_depth_mm'));
  }

  showDepth(j, drills, depthNow, dry, owner, jobDepth) {
    const bar = $('depth-bar');
    const text = $('depth-text');
    const d = drillFor(drills, j.block ?? 0);
    if (dry) {
      bar.max = 1; bar.value = 0;
      text.textContent = 'dry run: not drilled';
      bar.dataset.target = ''; bar.dataset.depth = '';
      return;
    }
    const target = d ? d[2] : null;
    // The running drill's own depth; between holes or at the end the job's deepest.
    const inDrill = d && d[0] === j.block && j.outcome === 'running';
    const depth = inDrill ? depthNow : jobDepth;
    bar.dataset.target = num(target) ? String(target) : '';
    bar.dataset.depth = num(depth) ? String(depth) : '';
    if (num(target) && target > 0) {
      bar.max = target;
      bar.value = num(depth) ? Math.min(Math.max(depth, 0), target) : 0;
      text.textContent = `${units.fmt(depth)} / ${units.fmt(target)} ${units.mode} (line ${d[1]})`;
    } else {
      bar.max = 1; bar.value = 0;
      text.textContent = owner === 'elsewhere' && num(depth)
        ? `${units.fmt(depth)} ${units.mode} (target not known here)` : '—';
    }
  }
}
