// The preview and the MDF plot: fetched as the state changes (debounced), each swapped
// in only when it is an image, the last good one kept while a value is wrong.
import { problemOf, request } from './api.js';
import { $ } from './dom.js';
import { clearErrors, routeErrors, setStatus, showError, showProblemSummary } from './errors.js';
import { liveQuery, mdfQuery, previewQuery } from './queries.js';
import { writeOutputs } from './share.js';
import { state, valueOf } from './state.js';

const DEBOUNCE_MS = 150;
let timer = null;
let seq = 0;
let inflight = null;

// A 503 shows its lines and the wait until the wrapper tries again.
function showBusy({ lines, wait, attempt, max }) {
  clearErrors();
  routeErrors([{ lines }]);
  setStatus(`The service is busy; trying again in ${wait} s (${attempt} of ${max})…`);
}

// Fetch an image; swap it in only when it is one, keeping the last good one.
async function loadImage(img, url, signal) {
  if (img.dataset.url === url) return { ok: true, url, kept: true };
  let resp;
  try {
    resp = await request(url, { signal, onBusy: showBusy });
  } catch (err) {
    if (err.name === 'AbortError') return { aborted: true };
    return { ok: false, status: 0, lines: ['Cannot reach the service: ' + err.message] };
  }
  if (!resp.ok) return { ok: false, status: resp.status, ...(await problemOf(resp)) };
  const blob = await resp.blob().catch(() => null);
  if (signal.aborted) return { aborted: true };
  if (!blob) return { ok: false, status: 0, lines: ['The image did not arrive whole'] };
  const old = img.src;
  img.src = URL.createObjectURL(blob);
  await img.decode().catch(() => {});
  img.dataset.url = url;
  if (old.startsWith('blob:')) URL.revokeObjectURL(old);
  return { ok: true, url };
}

// While a hand drags (the light pad or a slider), the preview shows draft renders as
// fast as the service returns them: at most one in flight, and when it lands the
// newest state is asked for next (the states passed over meanwhile are never sent).
// When the hand stops, the draft in flight is cancelled and the chosen request is
// rendered as usual.
const live = { active: false, inflight: null, pending: false, frames: 0 };

async function liveRender() {
  if (live.inflight) {
    live.pending = true;
    return;
  }
  if (!state.info || state.invalid.size) return;
  live.pending = false;
  live.inflight = new AbortController();
  const result = await loadImage($('#preview'), `/v1/render?${liveQuery()}`, live.inflight.signal);
  live.inflight = null;
  if (result.ok && !result.kept) {
    live.frames += 1;
    document.body.dataset.liveFrames = String(live.frames);
  }
  if (live.active && live.pending) liveRender();
}

export function startLive() {
  if (live.active) return;
  live.active = true;
  clearTimeout(timer);
  if (inflight) inflight.abort();  // the chosen render is asked for again at the end
  document.body.classList.remove('loading');
}

export function endLive() {
  if (!live.active) return;
  live.active = false;
  live.pending = false;
  if (live.inflight) live.inflight.abort();
  live.inflight = null;
  schedule(0);
}

export function schedule(delay = DEBOUNCE_MS) {
  document.body.dataset.busy = 'true';
  writeOutputs();
  clearTimeout(timer);
  if (live.active) {
    liveRender();
    return;
  }
  timer = setTimeout(update, delay);
}

function showInvalid() {
  // The fetch just aborted, if any, no longer ends its own loading state.
  document.body.classList.remove('loading');
  clearErrors();
  for (const [name, message] of state.invalid) showError(name, [message]);
  setStatus('Waiting for a valid value…');
  document.body.dataset.busy = 'false';
}

function showDone(results, started) {
  const job = state.info.resolved;
  $('#preview').alt = `Preview of ${state.preset}`;
  const npy = valueOf('format') === 'npy' ? ' · shown as PNG (npy is float data)' : '';
  const took = results.every((r) => r.kept) ? '' : ` · ${Math.round(performance.now() - started)} ms`;
  setStatus(`${state.preset} · ${valueOf('width') ?? job.width}×${valueOf('height') ?? job.height}` +
    ` · ${valueOf('quality')}${took}${npy}`);
}

async function update() {
  const mine = ++seq;
  if (inflight) inflight.abort();
  inflight = new AbortController();
  if (!state.info) return;
  if (state.invalid.size) {
    showInvalid();
    return;
  }
  const started = performance.now();
  document.body.classList.add('loading');
  const results = await Promise.all([
    loadImage($('#preview'), `/v1/render?${previewQuery()}`, inflight.signal),
    loadImage($('#mdf'), `/v1/mdf?${mdfQuery()}`, inflight.signal),
  ]);
  if (mine !== seq || results.some((r) => r.aborted)) return;
  document.body.classList.remove('loading');
  const failed = results.filter((r) => !r.ok);
  clearErrors();
  const preset = state.presetError ? [{ lines: [], fields: [{ field: 'preset', message: state.presetError }] }] : [];
  const names = routeErrors([...failed, ...preset]);
  if (failed.length) showProblemSummary(names);
  else showDone(results, started);
  document.body.dataset.busy = 'false';
}
