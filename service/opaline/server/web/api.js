// The one way the page talks to the service: every request goes through `request`,
// which sends the API key the user typed (when access control is on), asks for one on
// a 403, and retries a 503 after its Retry-After.
//
// With access control on, the service takes an API key (X-API-Key) on any request, or a
// signed URL for GET images; the page holds no signing key, so it always sends the key.
// The key is kept for this tab only (sessionStorage), sent as a header, never in a URL.
import { $, sleep } from './dom.js';

const KEY_STORE = 'opaline-api-key';
export const MAX_RETRIES = 5; // of a 503, each after its Retry-After

export const hasKey = () => Boolean(sessionStorage.getItem(KEY_STORE));

function withKey(headers = {}) {
  const key = sessionStorage.getItem(KEY_STORE);
  return key ? { ...headers, 'X-API-Key': key } : headers;
}

// A 403 means access control is on: ask for a key; saving it reloads the page.
function askForKey() {
  const form = $('#key-form');
  if (!form || !form.hidden) return;
  form.hidden = false;
  form.addEventListener('submit', (event) => {
    event.preventDefault();
    sessionStorage.setItem(KEY_STORE, $('#api-key').value.trim());
    location.reload();
  });
}

export const retryAfter = (resp) => Number(resp.headers.get('Retry-After')) || 1;

// fetch(url, options) with the key; `onBusy({ lines, wait, attempt, max })` is told of each
// 503 before its retry. A rejected fetch (network, abort) rejects as fetch does.
export async function request(url, { onBusy, ...options } = {}) {
  for (let attempt = 1; ; attempt += 1) {
    const resp = await fetch(url, { ...options, headers: withKey(options.headers) });
    if (resp.status === 403) askForKey();
    if (resp.status !== 503 || attempt > MAX_RETRIES) return resp;
    const wait = retryAfter(resp);
    const { lines } = await problemOf(resp.clone());
    onBusy?.({ lines, wait, attempt, max: MAX_RETRIES });
    await sleep(wait * 1000, options.signal);
  }
}

// An error answer: its lines (a 422 gives one per problem, other errors one) and, on a
// 422, the problems about a field ([{field, message}]).
export async function problemOf(resp) {
  const body = await resp.json().catch(() => null);
  const detail = body && body.detail;
  const lines = Array.isArray(detail) ? detail.map(String)
    : [detail ? String(detail) : `${resp.status} ${resp.statusText}`];
  return { lines, fields: (body && Array.isArray(body.fields)) ? body.fields : [] };
}

export async function getJSON(url) {
  const resp = await request(url);
  if (!resp.ok) {
    const { lines } = await problemOf(resp);
    throw Object.assign(new Error(lines.join('\n')), { status: resp.status });
  }
  return resp.json();
}

export function postJSON(url, body, options = {}) {
  return request(url, { ...options, method: 'POST',
    headers: { 'Content-Type': 'application/json' }, body: JSON.stringify(body) });
}
