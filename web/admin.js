// SPDX-License-Identifier: GPL-2.0-or-later
// rfbsim admin page logic: lists sim_manager's live and recent sessions from api/sessions every 2 s, ends a
// session on request, drains this host (no new participants) or takes it back, and in a cluster lists every host's
// live sessions. The page and the API share one origin, so the browser resends the admin credentials (HTTP Basic,
// the token as password) by itself. Every address is relative to the page (/admin, or /h2/admin under a host's path
// prefix behind a balancer), so the page works under any prefix.

const API = 'api/sessions';
const REFRESH_MS = 2000;
// The cluster view asks every host, through the balancer, less often than this host's own tables.
const CLUSTER_API = 'api/cluster';
const CLUSTER_REFRESH_MS = 5000;

// ---------------------------------------------------------------------------------------------------------------
// Page elements (all exist in admin.html).
// ---------------------------------------------------------------------------------------------------------------
const ui = {
  summary: document.getElementById('summary'),
  message: document.getElementById('message'),
  live: document.querySelector('#live tbody'),
  liveEmpty: document.getElementById('live-empty'),
  recent: document.querySelector('#recent tbody'),
  recentEmpty: document.getElementById('recent-empty'),
  hostState: document.getElementById('host-state'),
  drain: document.getElementById('drain'),
  clusterSection: document.getElementById('cluster-section'),
  clusterHosts: document.querySelector('#cluster-hosts tbody'),
  clusterSessions: document.querySelector('#cluster-sessions tbody'),
  clusterEmpty: document.getElementById('cluster-empty'),
};

// State, also readable by tests as window.rfbsimAdminState (read-only by convention).
const state = {
  updates: 0,         // answers from the API shown so far
  error: null,        // what went wrong with the last request, in words, or null
  lastUpdate: null,   // Date of the last answer shown
  draining: null,     // this host takes no new participants (true), takes them (false), or not known yet (null)
  cluster: null,      // the last cluster view: [{ id, prefix, reachable, error, draining, live, capacity }], or null
                      //   where this host is alone
};
window.rfbsimAdminState = state;

// ---------------------------------------------------------------------------------------------------------------
// Formatting.
// ---------------------------------------------------------------------------------------------------------------
const pad = (n) => String(n).padStart(2, '0');

// An ISO time from the API in local time: "HH:MM:SS" today, "YYYY-MM-DD HH:MM:SS" on other days; '' for null.
function formatTime(iso) {
  if (!iso) {
    return '';
  }
  const t = new Date(iso);
  if (Number.isNaN(t.getTime())) {
    return String(iso);
  }
  const time = `${pad(t.getHours())}:${pad(t.getMinutes())}:${pad(t.getSeconds())}`;
  return t.toDateString() === new Date().toDateString()
    ? time : `${t.getFullYear()}-${pad(t.getMonth() + 1)}-${pad(t.getDate())} ${time}`;
}

// A duration in milliseconds as "42 s", "3 min 05 s" or "1 h 02 min".
function formatDuration(ms) {
  if (!Number.isFinite(ms) || ms < 0) {
    return '';
  }
  const s = Math.floor(ms / 1000);
  if (s < 60) {
    return `${s} s`;
  }
  if (s < 3600) {
    return `${Math.floor(s / 60)} min ${pad(s % 60)} s`;
  }
  return `${Math.floor(s / 3600)} h ${pad(Math.floor((s % 3600) / 60))} min`;
}

const millisBetween = (fromIso, to) => to - new Date(fromIso).getTime();

// The stream's values from the API ("codec", "rtt_ms", "fps"; null when unknown or nobody watches), '\u2013' for
// unknown.
const DASH = '\u2013';
const formatCodec = (codec) => (typeof codec === 'string' && codec !== '' ? codec : DASH);
const formatNumber = (value, unit) => (Number.isFinite(value) ? `${value.toFixed(value < 10 ? 1 : 0)}${unit}` : DASH);

// ---------------------------------------------------------------------------------------------------------------
// Tables. Rows are kept per session id and updated in place, so a refresh never takes the keyboard focus away
// from a link or button, and screen readers are not told about cells that did not change.
// ---------------------------------------------------------------------------------------------------------------

// Sets a cell's text only when it changed.
function setText(cell, text) {
  if (cell.textContent !== text) {
    cell.textContent = text;
  }
}

// A cell showing a session state as a small badge.
function setState(cell, stateName, detail) {
  let badge = cell.firstElementChild;
  if (badge === null) {
    badge = document.createElement('span');
    cell.append(badge);
  }
  badge.className = `state state-${stateName}`;
  setText(badge, stateName);
  const extra = detail ? ` ${detail}` : '';
  if ((badge.nextSibling ? badge.nextSibling.textContent : '') !== extra) {
    if (badge.nextSibling) {
      badge.nextSibling.remove();
    }
    if (extra) {
      cell.append(extra);
    }
  }
}

// Makes a row of `classes.length` cells with those classes.
function makeRow(id, classes) {
  const row = document.createElement('tr');
  row.dataset.id = String(id);
  for (const cls of classes) {
    const cell = document.createElement('td');
    if (cls) {
      cell.className = cls;
    }
    row.append(cell);
  }
  return row;
}

// Brings tbody's rows in line with sessions (in that order): new ones made by make(session), every one updated by
// update(row, session), gone ones removed. Rows that stay are never moved out of the document.
function syncRows(tbody, sessions, make, update) {
  const rows = new Map([...tbody.rows].map((row) => [row.dataset.id, row]));
  const wanted = new Set(sessions.map((s) => String(s.id)));
  for (const [id, row] of rows) {
    if (!wanted.has(id)) {
      row.remove();
      rows.delete(id);
    }
  }
  sessions.forEach((session, index) => {
    let row = rows.get(String(session.id));
    if (!row) {
      row = make(session);
    }
    update(row, session);
    const there = tbody.rows[index] || null;
    if (there !== row) {
      tbody.insertBefore(row, there);
    }
  });
}

// Live sessions: id, participant, scenario, state, started, age, codec, round trip, frame rate, robot control,
// data folder, Watch and End. Watch opens the
// participant's page under /admin/watch/, where sim_manager relays it view-only: the researcher's keys and clicks
// never reach the session, and watching does not keep an idle session alive.
function makeLiveRow(session) {
  const row = makeRow(session.id, ['num', '', '', '', 'time', 'num', '', 'num', 'num', '', 'path', 'actions']);
  const actions = row.cells[11];
  const watch = document.createElement('a');
  watch.target = '_blank';
  watch.rel = 'noopener noreferrer';
  watch.textContent = 'Watch (view only)';
  const end = document.createElement('button');
  end.type = 'button';
  end.textContent = 'End';
  end.addEventListener('click', () => endSession(session.id, session.uid, end));
  actions.append(watch, end);
  return row;
}

function updateLiveRow(row, session, now) {
  const c = row.cells;
  setText(c[0], String(session.id));
  setText(c[1], session.uid);
  setText(c[2], session.scenario);
  setState(c[3], session.state, session.state === 'ending' && session.detail ? `(${session.detail})` : '');
  setText(c[4], formatTime(session.created_at));
  setText(c[5], formatDuration(millisBetween(session.created_at, now)));
  setText(c[6], formatCodec(session.codec));
  setText(c[7], formatNumber(session.rtt_ms, ' ms'));
  setText(c[8], formatNumber(session.fps, ''));
  setText(c[9], formatRobot(session));
  setText(c[10], session.data_path);
  const [watch, end] = c[11].children;
  // Relative to this page (its path prefix included), written out as a path so that it reads plainly.
  const href = session.token
    ? new URL(`admin/watch/${encodeURIComponent(session.token)}/`, document.baseURI).pathname : '';
  if (watch.getAttribute('href') !== href) {
    watch.setAttribute('href', href);
  }
  watch.hidden = href === '';
  watch.setAttribute('aria-label', `Watch session ${session.id} (${session.uid}), view only`);
  end.setAttribute('aria-label', `End session ${session.id} (${session.uid})`);
  if (session.state === 'ending') {
    end.disabled = true;
  }
}

// Recent (ended) sessions: id, participant, scenario, state, started, ended, duration, detail, exit status, folder,
// copied, robot control.
function makeRecentRow(session) {
  return makeRow(session.id, ['num', '', '', '', 'time', 'time', 'num', '', '', 'path', '', '']);
}

// Who drives the robot ("robot_control" from the API) and, when the session dials out to the lab's ROS, its
// namespace ("ros_namespace"): "external \u00b7 /rfbsim/s_12"; '\u2013' for a scenario without a robot.
function formatRobot(session) {
  if (!session.robot_control) {
    return DASH;
  }
  return session.ros_namespace ? `${session.robot_control} \u00b7 ${session.ros_namespace}` : session.robot_control;
}

// The after-session copy ("copy_state", "copy_attempts", "copy_error" from the API) in words: '\u2013' when none
// is configured, else its state and tries, with the last failure as the cell's tooltip.
function formatCopy(session) {
  const tries = session.copy_attempts === 1 ? '1 try' : `${session.copy_attempts} tries`;
  switch (session.copy_state) {
    case 'done': return session.copy_attempts > 1 ? `yes (${tries})` : 'yes';
    case 'pending': return session.copy_attempts > 0 ? `pending (${tries} failed)` : 'pending';
    case 'failed': return `FAILED (${tries})`;
    default: return DASH;
  }
}

function updateRecentRow(row, session) {
  const c = row.cells;
  setText(c[0], String(session.id));
  setText(c[1], session.uid);
  setText(c[2], session.scenario);
  setState(c[3], session.state, '');
  setText(c[4], formatTime(session.created_at));
  setText(c[5], formatTime(session.ended_at));
  const ended = session.ended_at ? new Date(session.ended_at).getTime() : NaN;
  setText(c[6], session.ended_at ? formatDuration(millisBetween(session.created_at, ended)) : '');
  setText(c[7], session.detail || '');
  setText(c[8], session.exit_status || '');
  setText(c[9], session.data_path);
  setText(c[10], formatCopy(session));
  if (c[10].title !== (session.copy_error || '')) {
    c[10].title = session.copy_error || '';
  }
  setText(c[11], formatRobot(session));
}

// ---------------------------------------------------------------------------------------------------------------
// Messages and the summary line.
// ---------------------------------------------------------------------------------------------------------------

// Shows a message ('error' or 'info'); '' hides it. The same text is not set again, so it is announced once.
function showMessage(text, kind = 'error') {
  ui.message.className = `message ${kind}`;
  setText(ui.message, text);
  ui.message.hidden = text === '';
}

function render(data) {
  const now = Date.now();
  const live = Array.isArray(data.live) ? [...data.live].sort((a, b) => a.id - b.id) : [];
  const recent = Array.isArray(data.recent) ? [...data.recent].sort((a, b) => b.id - a.id) : [];
  syncRows(ui.live, live, makeLiveRow, (row, s) => updateLiveRow(row, s, now));
  syncRows(ui.recent, recent, makeRecentRow, updateRecentRow);
  ui.liveEmpty.hidden = live.length > 0;
  ui.recentEmpty.hidden = recent.length > 0;
  state.lastUpdate = new Date(now);
  const time = formatTime(state.lastUpdate.toISOString());
  setText(ui.summary, `${live.length} of ${data.capacity} session slots in use \u00b7 updated ${time} ` +
                      `(every ${REFRESH_MS / 1000} s)`);
  showDraining(data.draining === true);
}

// ---------------------------------------------------------------------------------------------------------------
// Drain: the balancer's health and agent checks then send this host no new participants, while its live sessions
// (and their participants' rejoins) go on. The button switches it; the line says which way it stands.
// ---------------------------------------------------------------------------------------------------------------
function showDraining(draining) {
  state.draining = draining;
  setText(ui.hostState, draining
    ? 'Draining: this host takes no new sessions; its live ones go on.'
    : 'This host takes new sessions.');
  ui.hostState.className = draining ? 'draining' : '';
  setText(ui.drain, draining ? 'Take new sessions' : 'Drain this host');
  ui.drain.hidden = false;
}

async function switchDraining() {
  const drain = state.draining !== true;
  if (drain && !window.confirm('Drain this host? It takes no new sessions until you take it back; live sessions ' +
                               'go on.')) {
    return;
  }
  ui.drain.disabled = true;
  try {
    // The custom header proves the request comes from this page, as for End.
    const response = await fetch(drain ? 'api/drain' : 'api/undrain', {
      method: 'POST',
      cache: 'no-store',
      headers: { 'X-Rfbsim-Admin': '1' },
    });
    if (response.ok) {
      const host = await response.json();
      showDraining(host.draining === true);
      showMessage(host.draining ? 'This host is draining: no new sessions.' : 'This host takes new sessions again.',
                  'info');
    } else {
      showMessage(await describeFailure(response, drain ? 'drain this host' : 'take new sessions'), 'error');
    }
  } catch (err) {
    showMessage(`Could not switch draining: the server cannot be reached (${err.message}).`, 'error');
  }
  ui.drain.disabled = false;
}

ui.drain.addEventListener('click', switchDraining);

// ---------------------------------------------------------------------------------------------------------------
// The cluster view: api/cluster names every host and its path prefix on the balancer's origin; each host's
// api/sessions is asked there. A host that does not answer (down, or the balancer's 503) is shown as unreachable.
// ---------------------------------------------------------------------------------------------------------------

// The balancer's root path: this page's folder less this host's own prefix ("/h2/" -> "/").
function clusterRoot(ownPrefix) {
  const folder = new URL('.', document.baseURI).pathname;
  const own = `${ownPrefix || ''}/`;
  return ownPrefix && folder.endsWith(own) ? folder.slice(0, folder.length - own.length + 1) : folder;
}

// One host's live sessions and load, or why they could not be had.
async function fetchHost(root, host) {
  const url = `${root}${host.prefix ? `${host.prefix.slice(1)}/` : ''}api/sessions`;
  const view = { id: host.id, prefix: host.prefix, reachable: false, error: '', draining: false, live: [],
                 capacity: null };
  try {
    const response = await fetch(url, { cache: 'no-store', headers: { Accept: 'application/json' } });
    if (!response.ok) {
      view.error = `HTTP ${response.status}`;
      return view;
    }
    const data = await response.json();
    view.reachable = true;
    view.draining = data.draining === true;
    view.live = Array.isArray(data.live) ? data.live : [];
    view.capacity = Number.isFinite(data.capacity) ? data.capacity : null;
  } catch (err) {
    view.error = err.message;
  }
  return view;
}

function renderCluster(hosts) {
  syncRows(ui.clusterHosts, hosts, (host) => makeRow(host.id, ['', '', 'num']),
           (row, host) => {
             const c = row.cells;
             setText(c[0], host.id);
             const words = !host.reachable ? `unreachable (${host.error})` : host.draining ? 'draining' : 'up';
             setText(c[1], words);
             c[1].className = !host.reachable ? 'unreachable' : host.draining ? 'draining' : '';
             setText(c[2], host.reachable ? `${host.live.length} of ${host.capacity ?? '?'}` : DASH);
           });
  const sessions = hosts.flatMap((host) => host.live.map((s) => ({ ...s, host: host.id, id: `${host.id}/${s.id}`,
                                                                   number: s.id })));
  syncRows(ui.clusterSessions, sessions, (s) => makeRow(s.id, ['', 'num', '', '', '', 'time']), (row, s) => {
    const c = row.cells;
    setText(c[0], s.host);
    setText(c[1], String(s.number));
    setText(c[2], s.uid);
    setText(c[3], s.scenario);
    setState(c[4], s.state, '');
    setText(c[5], formatTime(s.created_at));
  });
  ui.clusterEmpty.hidden = sessions.length > 0;
}

async function refreshCluster() {
  let cluster;
  try {
    const response = await fetch(CLUSTER_API, { cache: 'no-store', headers: { Accept: 'application/json' } });
    if (!response.ok) {
      return;   // an older manager without the cluster API, or not authorised: the main tables say so
    }
    cluster = await response.json();
  } catch (err) {
    return;
  }
  const hosts = Array.isArray(cluster.hosts) ? cluster.hosts : [];
  if (hosts.length < 2) {
    state.cluster = null;
    ui.clusterSection.hidden = true;
    return;
  }
  const root = clusterRoot(typeof cluster.prefix === 'string' ? cluster.prefix : '');
  state.cluster = await Promise.all(hosts.map((host) => fetchHost(root, host)));
  renderCluster(state.cluster);
  ui.clusterSection.hidden = false;
}

async function clusterLoop() {
  await refreshCluster();
  setTimeout(clusterLoop, CLUSTER_REFRESH_MS);
}

// ---------------------------------------------------------------------------------------------------------------
// The API.
// ---------------------------------------------------------------------------------------------------------------

// What a failed response means, in words.
async function describeFailure(response, what) {
  if (response.status === 401) {
    return `Not authorised (HTTP 401) to ${what}. Reload this page and log in with the admin token as the ` +
           'password (any user name).';
  }
  let detail = '';
  try {
    const body = await response.json();
    detail = body && body.error ? `: ${body.error}` : '';
  } catch (err) {
    // not JSON: the status says enough
  }
  return `Could not ${what} (HTTP ${response.status}${detail}).`;
}

async function refresh() {
  try {
    const response = await fetch(API, { cache: 'no-store', headers: { Accept: 'application/json' } });
    if (!response.ok) {
      state.error = await describeFailure(response, 'list the sessions');
    } else {
      render(await response.json());
      state.updates += 1;
      state.error = null;
    }
  } catch (err) {
    state.error = `The server cannot be reached (${err.message}). Retrying every ${REFRESH_MS / 1000} s.`;
  }
  if (state.error !== null) {
    showMessage(state.error, 'error');
  } else if (ui.message.classList.contains('error')) {
    showMessage('');
  }
}

// Ends a live session after the researcher confirms; the next refresh shows it ending.
async function endSession(id, uid, button) {
  const question = `End session ${id} of participant ${uid} now? Their simulation stops and cannot be resumed.`;
  if (!window.confirm(question)) {
    return;
  }
  button.disabled = true;
  try {
    // The custom header proves the request comes from this page: other sites cannot send it without CORS.
    const response = await fetch(`${API}/${encodeURIComponent(id)}/end`, {
      method: 'POST',
      cache: 'no-store',
      headers: { 'X-Rfbsim-Admin': '1' },
    });
    if (response.ok) {
      showMessage(`Session ${id} (${uid}) is ending.`, 'info');
    } else {
      showMessage(await describeFailure(response, `end session ${id}`), 'error');
      button.disabled = false;
    }
  } catch (err) {
    showMessage(`Could not end session ${id}: the server cannot be reached (${err.message}).`, 'error');
    button.disabled = false;
  }
  await refresh();
}

// Refreshes now, then REFRESH_MS after each answer (so slow answers never pile up).
async function refreshLoop() {
  await refresh();
  setTimeout(refreshLoop, REFRESH_MS);
}

refreshLoop();
clusterLoop();
