// lucent serve's page: a thin view of the screen the server says is current (the
// server owns the plan and the state; a reload asks it again). Keys 1-7, arrows and
// Enter, and clicks follow the lab's rules (study/session/rating_input.h); each answer
// sends its input events with performance.now() times, and the server replays them.
// The picture is drawn pixel for pixel; its onset is the first requestAnimationFrame
// after it decoded and entered the page. A forced choice (pair, triad, quadruple, a
// staircase's pair or odd one out) shows its pictures side by side, or its two parts in
// sequence with a blank between and then the two answers; arrows or digits pick, Enter
// confirms, a click answers. An adjustment shows the target and the match, which the
// arrows (Shift: fine), the wheel and a drag move over its pre-rendered series exactly
// as the lab's AdjustInput moves the knob (study/session/adjust_input.cpp); Enter sends.
'use strict';
(() => {
  const el = (id) => document.getElementById(id);
  const params = new URLSearchParams(location.search);
  const who = {};
  if (params.get('participant')) who.participant = params.get('participant');
  if (params.get('PROLIFIC_PID')) {
    who.prolific = { PROLIFIC_PID: params.get('PROLIFIC_PID') };
    if (params.get('STUDY_ID')) who.prolific.STUDY_ID = params.get('STUDY_ID');
    if (params.get('SESSION_ID')) who.prolific.SESSION_ID = params.get('SESSION_ID');
  }
  const code = who.participant || (who.prolific && who.prolific.PROLIFIC_PID) || '';
  const tokenKey = 'lucent-token:' + code;

  let state = null;     // the server's last reply
  let token = null;
  let shownAt = null;   // performance.now() of the current screen's first frame
  let busy = false;     // a request is on its way: input waits
  let trial = null;     // the rating screen: onset, events, ratings, focus
  let choice = null;    // a forced choice's answer screen: onsets, events, the pick
  let adjust = null;    // an adjustment: onset, events, position on the scale, index

  function mark(screen) {
    document.body.dataset.screen = screen;
    document.body.dataset.view = state && state.view !== undefined ? String(state.view) : '';
  }
  function only(id) {
    for (const m of ['text-screen', 'trial-screen', 'message'])
      el(m).hidden = m !== id;
  }
  function message(text, screen) {
    only('message');
    el('progress').hidden = true;
    el('message-text').textContent = text;
    mark(screen || 'error');
  }
  function firstFrame() {
    return new Promise((resolve) => requestAnimationFrame(() => resolve(performance.now())));
  }
  let refreshHz = null;  // the display's refresh, once measured
  function client() {
    const c = {
      user_agent: navigator.userAgent, window_width: innerWidth, window_height: innerHeight,
      device_pixel_ratio: devicePixelRatio, screen_width: screen.width,
      screen_height: screen.height,
    };
    if (refreshHz) c.refresh_hz = refreshHz;
    return c;
  }

  // Every call is safe to send again (an answer names its trial and view; the server
  // stores the same answer once), so a lost reply, a proxy's 502/504 or a busy or
  // restarting server (503) is retried with backoff (Retry-After when given) for about
  // a minute before the page says the server cannot be reached.
  const kRetryDelaysMs = [250, 500, 1000, 2000, 4000, 8000, 8000, 8000, 8000, 8000];
  async function api(endpoint, body) {
    if (token && !body.token) body.token = token;
    // The server keeps nothing of a page before consent: it says who and what it is
    // with every call.
    if (!body.client) body.client = client();
    for (const key in who) if (!(key in body)) body[key] = who[key];
    const text = JSON.stringify(body);
    for (let attempt = 0; ; ++attempt) {
      let status = 0, reply, retryAfterMs = 0;
      try {
        const r = await fetch('/api/' + endpoint, {
          method: 'POST', headers: { 'Content-Type': 'application/json' },
          body: text, cache: 'no-store',
        });
        status = r.status;
        retryAfterMs = 1000 * (Number(r.headers.get('Retry-After')) || 0);
        try { reply = await r.json(); } catch (e) { reply = { error: 'no reply (' + r.status + ')' }; }
      } catch (e) {
        reply = { error: 'the study server cannot be reached: ' + e.message };
      }
      const transient = status === 0 || status === 502 || status === 503 || status === 504;
      if (!transient || attempt >= kRetryDelaysMs.length) return { status, reply };
      document.body.dataset.retries = String(Number(document.body.dataset.retries || 0) + 1);
      await new Promise((resolve) =>
        setTimeout(resolve, Math.max(kRetryDelaysMs[attempt], retryAfterMs)));
    }
  }
  // 200: the next screen; 409: the page is behind the server (another tab, a restart),
  // so it asks again; anything else is shown.
  function settle(status, reply) {
    busy = false;
    if (status === 200 && reply.token) {
      token = reply.token;
      localStorage.setItem(tokenKey, token);
    }
    if (status === 200) return show(reply);
    if (status === 409 || status === 0) return setTimeout(start, status ? 0 : 2000);
    if (status === 410) localStorage.removeItem(tokenKey);  // withdrawn: the key is spent
    message(reply.error || 'error ' + status);
  }

  async function start() {
    if (!code) return message('This link has no participant code (?participant=ID).');
    const body = Object.assign({ t_ms: performance.now(), client: client() }, who);
    const saved = localStorage.getItem(tokenKey);
    if (saved) body.token = saved;
    busy = true;
    const { status, reply } = await api('session', body);
    busy = false;
    if (status !== 200) return message(reply.error || 'error ' + status);
    if (reply.token) {
      token = reply.token;
      localStorage.setItem(tokenKey, token);
    }
    show(reply);
    if (reply.token) measureRefresh();
  }

  // The display's refresh from 60 frame intervals (median), stored with the session.
  async function measureRefresh() {
    const times = [];
    for (let i = 0; i < 61; ++i) times.push(await firstFrame());
    const gaps = times.slice(1).map((t, i) => t - times[i]).sort((a, b) => a - b);
    const median = gaps[Math.floor(gaps.length / 2)];
    if (median > 0) {
      refreshHz = 1000 / median;
      await api('environment', { refresh_hz: refreshHz });
    }
    document.body.dataset.refreshSent = '1';  // (tests wait for it)
  }

  function show(s) {
    state = s;
    shownAt = null;
    trial = null;
    choice = null;
    adjust = null;
    document.body.style.background = s.background || '#000';
    const progress = s.progress;
    el('progress').hidden = !progress || s.screen === 'consent';
    if (progress) el('progress').textContent = progress.done + ' of ' + progress.total;
    if (s.screen === 'done') return finish(s);
    if (s.screen === 'declined') {
      localStorage.removeItem(tokenKey);
      return message(s.text, 'declined');
    }
    if (s.screen === 'trial') {
      // The server names the screen the trial's kind is answered on.
      if (s.trial.screen === 'adjust') return beginAdjust(s);
      return s.trial.screen === 'scales' ? beginTrial(s) : beginChoice(s);
    }
    only('text-screen');
    el('text').textContent = s.text;
    const consent = s.screen === 'consent';
    el('decline').hidden = !consent;
    el('continue').textContent = consent ? 'I agree (Enter)' : 'Continue (Enter)';
    // Shown with its first frame: keys before it were meant for the screen before.
    firstFrame().then((t) => {
      if (state !== s) return;
      shownAt = t;
      mark(s.screen);
    });
  }

  function finish(s) {
    localStorage.removeItem(tokenKey);
    const c = s.completion || {};
    let text = s.text;
    if (c.code) text += '\n\nYour completion code: ' + c.code;
    if (c.url) text += '\n\nTaking you back now...';
    message(text, 'done');
    if (c.code) document.body.dataset.completionCode = c.code;
    if (c.url) setTimeout(() => location.assign(c.url), 1500);
  }

  function act(endpoint, t) {
    if (busy || shownAt === null || t < shownAt) return;  // a key meant for the screen before
    busy = true;
    api(endpoint, { view: state.view, shown_ms: shownAt, t_ms: t })
      .then(({ status, reply }) => settle(status, reply));
  }

  // ---- the rating screen ------------------------------------------------------------
  const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

  // A trial's own scales: the study's questions, or its kind's question.
  const scalesOf = (s) => s.trial.questions || s.questions;

  function buildQuestions(s) {
    const box = el('questions');
    box.textContent = '';
    scalesOf(s).forEach((q, qi) => {
      const div = document.createElement('div');
      div.className = 'question';
      const text = document.createElement('div');
      text.textContent = q.text;
      div.appendChild(text);
      const scale = document.createElement('div');
      scale.className = 'scale';
      const left = document.createElement('span');
      left.className = 'label left';
      left.textContent = q.labels[0] || '';
      scale.appendChild(left);
      for (let v = 1; v <= q.labels.length; ++v) {
        const b = document.createElement('button');
        b.type = 'button';
        b.textContent = String(v);
        b.dataset.question = String(qi);
        b.dataset.value = String(v);
        b.addEventListener('click', (ev) => {
          ev.currentTarget.blur();  // Enter stays the study's key, not the button's
          input({ type: 'point', question: qi, value: v }, ev.timeStamp);
        });
        scale.appendChild(b);
      }
      const right = document.createElement('span');
      right.className = 'label right';
      right.textContent = q.labels[q.labels.length - 1] || '';
      scale.appendChild(right);
      div.appendChild(scale);
      box.appendChild(div);
    });
  }

  // True when the page shows the picture at its size and the scales without scrolling.
  function fits() {
    const root = document.documentElement;
    return root.scrollWidth <= innerWidth && root.scrollHeight <= innerHeight;
  }

  // Lays the trial screen out invisibly with layOut() (true when it fits) until it fits
  // the window; while it does not, says what is too small ("the picture at its true size
  // (...)") and waits for a resize. False when the session moved on meanwhile.
  async function waitUntilItFits(s, layOut, what) {
    for (;;) {
      only('trial-screen');
      if (layOut()) return true;
      message('Your browser window is too small to show ' + what + '. Please enlarge ' +
              'the window or zoom out; the study continues by itself.', 'too-small');
      await new Promise((resolve) => addEventListener('resize', resolve, { once: true }));
      if (state !== s) return false;
    }
  }

  async function beginTrial(s) {
    const t = s.trial;
    el('rating-part').hidden = false;
    el('choice-part').hidden = true;
    el('adjust-part').hidden = true;
    el('trial-screen').classList.remove('choice');
    only('trial-screen');
    const screenBox = el('trial-screen');
    screenBox.style.visibility = 'hidden';  // the blank between trials
    mark('blank');
    const img = new Image();
    img.alt = '';
    img.src = t.image;
    const decoded = img.decode();
    await sleep(t.blank_ms);
    try { await decoded; } catch (e) { return message('The picture ' + t.image + ' cannot be shown.'); }
    if (state !== s) return;
    // One image pixel per device pixel: the CSS size divides by devicePixelRatio.
    const size = () => {
      img.style.width = t.width / devicePixelRatio + 'px';
      img.style.height = t.height / devicePixelRatio + 'px';
    };
    el('picture').textContent = '';
    el('picture').appendChild(img);
    el('prompt').textContent = t.prompt || (t.practice ? 'Practice' : '');
    buildQuestions(s);
    if (!await waitUntilItFits(s, () => { size(); return fits(); },
                               'the picture at its true size (' + t.width + ' x ' +
                               t.height + ' pixels) with the rating scales')) return;
    only('trial-screen');
    el('progress').hidden = !s.progress;
    screenBox.style.visibility = 'visible';
    const onset = await firstFrame();
    if (state !== s) return;
    trial = {
      onset, events: [], focus: 0, ratings: scalesOf(s).map(() => null),
      points: scalesOf(s).map((q) => q.labels.length),
    };
    render();
    document.body.dataset.trial = t.id;
    mark('trial');
  }

  function render() {
    document.querySelectorAll('.question').forEach((div, qi) => {
      div.classList.toggle('focused', qi === trial.focus);
      div.querySelectorAll('button').forEach((b) =>
        b.classList.toggle('chosen', Number(b.dataset.value) === trial.ratings[qi]));
    });
    el('next').disabled = !trial.ratings.every((r) => r !== null);
  }

  // One input on the rating screen, by the lab's rules; recorded for the server's replay.
  function input(ev, t) {
    if (!trial || busy || t < trial.onset) return;
    const rec = Object.assign({ t_ms: t }, ev);
    const n = trial.ratings.length;
    const set = (q, v) => { if (v >= 1 && v <= trial.points[q]) trial.ratings[q] = v; };
    const all = () => trial.ratings.every((r) => r !== null);
    let confirm = false;
    if (ev.type === 'point') {
      trial.focus = ev.question;
      set(ev.question, ev.value);
    } else if (ev.type === 'next') {
      if (!all()) return;
      confirm = true;
    } else {
      const k = ev.key, f = trial.focus, r = trial.ratings[f], p = trial.points[f];
      const middle = Math.floor((p + 1) / 2);
      if (k >= '1' && k <= '9' && k.length === 1) {
        if (Number(k) > Math.max(...trial.points)) return;
        set(f, Number(k));
      } else if (k === 'ArrowLeft') set(f, r ? Math.max(1, r - 1) : middle);
      else if (k === 'ArrowRight') set(f, r ? Math.min(p, r + 1) : middle);
      else if (k === 'ArrowUp') trial.focus = Math.max(0, f - 1);
      else if (k === 'ArrowDown') trial.focus = Math.min(n - 1, f + 1);
      else if (k === 'Enter') {
        if (!r) return;
        if (all()) confirm = true;
        else {
          for (let step = 1; step <= n; ++step)
            if (trial.ratings[(f + step) % n] === null) { trial.focus = (f + step) % n; break; }
        }
      } else return;
    }
    trial.events.push(rec);
    render();
    if (!confirm) return;
    busy = true;
    const body = { trial: state.trial.id, view: state.view, onset_ms: trial.onset, events: trial.events };
    trial = null;
    api('answer', body).then(({ status, reply }) => settle(status, reply));
  }

  // ---- a forced choice --------------------------------------------------------------
  // Which pictures (indices into `shown`) each alternative is, as the trial's kind says
  // (TrialKind::answer_groups): a pair's two pictures, a staircase's two or three, a
  // triad's pairs (a, b) and (b, c), a quadruple's pairs (a, b) and (c, d).
  function partsOf(t) { return t.groups; }
  // Groups that share a picture (a triad's): one row with each group's answer
  // bracketing it below, the two meeting at the shared picture.
  function sharesPictures(parts) {
    const seen = new Set();
    for (const group of parts)
      for (const i of group) {
        if (seen.has(i)) return true;
        seen.add(i);
      }
    return false;
  }
  function answerButton(label, alternative) {
    const b = document.createElement('button');
    b.type = 'button';
    b.className = 'answer';
    b.textContent = label;
    b.dataset.alternative = String(alternative);
    return b;
  }
  // Side by side: each answer's pictures as a group with its answer below it (a wider
  // gap between groups of several pictures, a quadruple's pairs); groups sharing a
  // picture (a triad's) as one row with each group's answer bracketing it below. `part`
  // (0, 1) lays out one part of a sequence instead, and 'answer' its answers alone.
  function layoutChoice(t, imgs, part) {
    const box = el('alternatives');
    box.textContent = '';
    const parts = partsOf(t);
    box.className = parts.every((group) => group.length > 1) ? 'groups-apart' : '';
    if (part === 'answer') {
      box.classList.add('answers');
      t.labels.forEach((label, i) => box.appendChild(answerButton(label, i + 1)));
      return;
    }
    if (part !== undefined) {  // one part of a sequence: its pictures only
      const group = document.createElement('div');
      group.className = 'group';
      for (const i of parts[part]) group.appendChild(imgs[i]);  // moved, never copied
      box.classList.add('sequence');
      box.appendChild(group);
      return;
    }
    if (sharesPictures(parts)) {
      const grid = document.createElement('div');
      grid.className = 'shared';
      grid.style.gridTemplateColumns = 'repeat(' + imgs.length + ', auto)';
      imgs.forEach((img, i) => {  // a click on a picture only one answer names picks it
        const naming = parts.flatMap((group, k) => (group.includes(i) ? [k + 1] : []));
        img.dataset.alternative = naming.length === 1 ? String(naming[0]) : '';
        grid.appendChild(img);
      });
      parts.forEach((group, i) => {
        const bracket = answerButton(t.labels[i], i + 1);
        bracket.classList.add('bracket');
        bracket.style.gridColumn =
          Math.min(...group) + 1 + ' / ' + (Math.max(...group) + 2);
        bracket.style.gridRow = String(i + 2);
        grid.appendChild(bracket);
      });
      box.appendChild(grid);
      return;
    }
    parts.forEach((indices, i) => {
      const group = document.createElement('div');
      group.className = 'group';
      group.dataset.alternative = String(i + 1);
      const pictures = document.createElement('div');
      pictures.className = 'pictures';
      for (const k of indices) pictures.appendChild(imgs[k]);
      group.appendChild(pictures);
      group.appendChild(answerButton(t.labels[i], i + 1));
      box.appendChild(group);
    });
  }
  function sizeChoice(t) {
    // One image pixel per device pixel, as for a rating's picture.
    el('alternatives').querySelectorAll('img').forEach((img) => {
      const k = Number(img.dataset.index);
      img.style.width = t.shown[k].width / devicePixelRatio + 'px';
      img.style.height = t.shown[k].height / devicePixelRatio + 'px';
    });
  }
  // Waits (frame by frame at the end) until performance.now() reaches `t`.
  async function until(t) {
    const early = t - performance.now() - 20;
    if (early > 0) await sleep(early);
    while (performance.now() < t) await firstFrame();
  }

  async function beginChoice(s) {
    const t = s.trial;
    el('rating-part').hidden = true;
    el('choice-part').hidden = false;
    el('adjust-part').hidden = true;
    const screenBox = el('trial-screen');
    screenBox.classList.add('choice');
    el('alternatives').style.visibility = '';
    only('trial-screen');
    screenBox.style.visibility = 'hidden';  // the blank between trials
    mark('blank');
    const imgs = t.shown.map((picture, k) => {
      const img = new Image();
      img.alt = '';
      img.draggable = false;
      img.dataset.index = String(k);
      img.src = picture.image;
      return img;
    });
    const decoded = Promise.all(imgs.map((img) => img.decode()));
    await sleep(t.blank_ms);
    try { await decoded; } catch (e) { return message('The pictures of this trial cannot be shown.'); }
    if (state !== s) return;
    el('choice-prompt').textContent = t.practice ? 'Practice' : '';
    el('question').textContent = t.question;
    const sequential = t.presentation === 'sequential';
    // Every layout the trial shows must fit at the pictures' true size.
    const layouts = sequential ? [0, 1, 'answer'] : [undefined];
    const everyLayoutFits = () => {
      let ok = true;
      for (const part of layouts) {
        layoutChoice(t, imgs, part);
        sizeChoice(t);
        ok = ok && fits();
      }
      return ok;
    };
    const widths = t.shown.map((p) => p.width + ' x ' + p.height).join(', ');
    if (!await waitUntilItFits(s, everyLayoutFits, 'the pictures side by side at their ' +
                               'true size (' + widths + ' pixels)')) return;
    only('trial-screen');
    el('progress').hidden = !s.progress;
    layoutChoice(t, imgs, layouts[0]);
    sizeChoice(t);
    screenBox.style.visibility = 'visible';
    const onset = await firstFrame();
    if (state !== s) return;
    let answerOnset = onset;
    let phases;
    if (sequential) {
      // Each part for its duration, counted from the frame that showed it (the server
      // refuses a part shown before the one before had its time).
      document.body.dataset.trial = t.id;
      mark('sequence');
      const seq = t.sequence;
      await until(onset + seq.duration_ms);
      if (state !== s) return;
      el('alternatives').style.visibility = 'hidden';
      const gap = await firstFrame();
      await until(gap + seq.blank_ms);
      if (state !== s) return;
      layoutChoice(t, imgs, 1);
      sizeChoice(t);
      el('alternatives').style.visibility = 'visible';
      const second = await firstFrame();
      await until(second + seq.duration_ms);
      if (state !== s) return;
      layoutChoice(t, imgs, 'answer');
      answerOnset = await firstFrame();
      if (state !== s) return;
      phases = { gap, second, answer: answerOnset };
    }
    choice = { onset, answerOnset, phases, events: [], pick: null };
    el('alternatives').querySelectorAll('[data-alternative]').forEach((node) => {
      const alternative = Number(node.dataset.alternative);
      if (!alternative) return;
      node.addEventListener('click', (ev) => {
        ev.stopPropagation();  // an answer inside its group: one click, one event
        if (ev.currentTarget.blur) ev.currentTarget.blur();  // Enter stays the study's key
        choiceInput({ type: 'choice', alternative }, ev.timeStamp);
      });
    });
    renderChoice();
    document.body.dataset.trial = t.id;
    mark('trial');
  }

  function renderChoice() {
    const t = state.trial;
    const parts = partsOf(t);
    el('alternatives').querySelectorAll('[data-alternative]').forEach((node) =>
      node.classList.toggle('chosen', Number(node.dataset.alternative) === choice.pick));
    if (sharesPictures(parts))  // the chosen group's pictures
      el('alternatives').querySelectorAll('img').forEach((img) =>
        img.classList.toggle('chosen', choice.pick !== null &&
                             parts[choice.pick - 1].includes(Number(img.dataset.index))));
    document.body.dataset.choice = choice.pick === null ? '' : String(choice.pick);
  }

  // One input on a forced choice's answer screen, by the lab's rules: of two, the
  // arrows pick the alternative on their side; of three (an odd one out), the first
  // arrow picks the middle one and the next move by one; a digit picks, Enter confirms,
  // a click picks and confirms. Recorded for the server's replay.
  function choiceInput(ev, t) {
    if (!choice || busy || t < choice.answerOnset) return;
    const n = state.trial.labels.length;  // the answers
    let confirm = false;
    if (ev.type === 'choice') {
      choice.pick = ev.alternative;
      confirm = true;
    } else {
      const k = ev.key, p = choice.pick, middle = Math.floor((n + 1) / 2);
      if (k.length === 1 && k >= '1' && k <= String(n)) choice.pick = Number(k);
      else if (k === 'ArrowLeft') choice.pick = n === 2 ? 1 : p ? Math.max(1, p - 1) : middle;
      else if (k === 'ArrowRight') choice.pick = n === 2 ? 2 : p ? Math.min(n, p + 1) : middle;
      else if (k === 'Enter') {
        if (choice.pick === null) return;
        confirm = true;
      } else return;  // nothing else answers a choice
    }
    choice.events.push(Object.assign({ t_ms: t }, ev));
    renderChoice();
    if (!confirm) return;
    busy = true;
    const body = {
      trial: state.trial.id, view: state.view, onset_ms: choice.onset, events: choice.events,
    };
    if (choice.phases) body.phase_onsets_ms = choice.phases;
    choice = null;
    api('answer', body).then(({ status, reply }) => settle(status, reply));
  }

  // ---- an adjustment ----------------------------------------------------------------
  async function beginAdjust(s) {
    const t = s.trial;
    el('rating-part').hidden = true;
    el('choice-part').hidden = true;
    el('adjust-part').hidden = false;
    const screenBox = el('trial-screen');
    screenBox.classList.add('choice');  // the whole width, as a forced choice's row
    only('trial-screen');
    screenBox.style.visibility = 'hidden';  // the blank between trials
    mark('blank');
    const picture = (url) => {
      const img = new Image();
      img.alt = '';
      img.draggable = false;
      img.src = url;
      return img;
    };
    // Every picture of the series loaded and decoded before the onset: a move never
    // waits for one (the browser caches them for the block's next trials).
    const target = picture(t.target.image);
    const series = t.series.map(picture);
    const decoded = Promise.all([target, ...series].map((img) => img.decode()));
    await sleep(t.blank_ms);
    try { await decoded; } catch (e) { return message('The pictures of this trial cannot be shown.'); }
    if (state !== s) return;
    el('adjust-prompt').textContent = t.practice ? 'Practice' : '';
    el('adjust-question').textContent = t.question;
    el('target').textContent = '';
    el('target').appendChild(target);
    const size = () => {  // one image pixel per device pixel, as everywhere
      target.style.width = t.target.width / devicePixelRatio + 'px';
      target.style.height = t.target.height / devicePixelRatio + 'px';
      for (const img of series) {
        img.style.width = t.match.width / devicePixelRatio + 'px';
        img.style.height = t.match.height / devicePixelRatio + 'px';
      }
    };
    const showMatch = (i) => {
      el('match').textContent = '';
      el('match').appendChild(series[i]);
      document.body.dataset.matchIndex = String(i);
    };
    showMatch(t.start_index);
    if (!await waitUntilItFits(s, () => { size(); return fits(); },
                               'the two pictures side by side at their true size (' +
                               t.target.width + ' x ' + t.target.height + ' and ' +
                               t.match.width + ' x ' + t.match.height + ' pixels)')) return;
    only('trial-screen');
    el('progress').hidden = !s.progress;
    screenBox.style.visibility = 'visible';
    const onset = await firstFrame();
    if (state !== s) return;
    // The position on the scale of the start's picture, as AdjustInput computes it.
    const last = t.series.length - 1;
    adjust = {
      t, onset, events: [], index: t.start_index, showMatch,
      position: t.low + (t.high - t.low) * t.start_index / last,
      dragging: false, lastX: 0, pendingDx: 0,
    };
    document.body.dataset.trial = t.id;
    mark('trial');
  }

  // The series index nearest `position` (AdjustInput::series_index_at; Math.round and
  // std::round agree on the non-negative values it rounds).
  function indexAt(a, position) {
    const last = a.t.series.length - 1;
    const at = Math.round((position - a.t.low) / (a.t.high - a.t.low) * last);
    return Math.min(Math.max(at, 0), last);
  }
  // AdjustInput::move_to: the position held inside the range; false when it did not
  // move (a step past an end), which the page neither shows nor sends.
  function moveTo(a, position) {
    position = Math.min(Math.max(position, a.t.low), a.t.high);
    if (position === a.position) return false;
    a.position = position;
    const index = indexAt(a, position);
    if (index !== a.index) {
      a.index = index;
      a.showMatch(index);
    }
    return true;
  }

  // One input on the adjust screen, applied as the server will replay it, and recorded.
  function adjustInput(ev, t) {
    const a = adjust;
    if (!a || busy || t < a.onset) return;
    if (ev.type === 'key' && ev.key === 'Enter') {
      a.events.push({ t_ms: t, type: 'key', key: 'Enter' });
      busy = true;
      const body = { trial: state.trial.id, view: state.view, onset_ms: a.onset, events: a.events };
      adjust = null;
      api('answer', body).then(({ status, reply }) => settle(status, reply));
      return;
    }
    if (a.events.length >= a.t.max_events - 1) return;  // the answer's bound: room for Enter
    const range = a.t.high - a.t.low;
    let moved = false;
    if (ev.type === 'key') {
      const up = ev.key === 'ArrowRight' || ev.key === 'ArrowUp';
      if (!up && ev.key !== 'ArrowLeft' && ev.key !== 'ArrowDown') return;
      const by = ev.shift ? a.t.fine : a.t.coarse;
      moved = moveTo(a, a.position + (up ? by : -by));
    } else if (ev.type === 'wheel') {
      moved = moveTo(a, a.position + ev.notches * a.t.coarse);
    } else if (ev.type === 'drag') {
      moved = moveTo(a, a.position + ev.dx / ev.width * range);
    }
    if (moved) a.events.push(Object.assign({ t_ms: t }, ev));
  }

  // The wheel anywhere: one coarse step per event, up (away from the participant) up.
  document.addEventListener('wheel', (ev) => {
    if (!adjust) return;
    ev.preventDefault();
    if (ev.deltaY === 0) return;
    adjustInput({ type: 'wheel', notches: -Math.sign(ev.deltaY) }, ev.timeStamp);
  }, { passive: false });
  // A drag that starts on the match: its width spans the range. Mouse moves add up until
  // they would show another picture, and go as one event (an answer holds at most
  // max_events); the page applies exactly what it sends, so it shows what the server
  // will store.
  el('match').addEventListener('mousedown', (ev) => {
    if (!adjust || ev.button !== 0) return;
    ev.preventDefault();
    adjust.dragging = true;
    adjust.lastX = ev.clientX;
    adjust.pendingDx = 0;
  });
  document.addEventListener('mousemove', (ev) => {
    const a = adjust;
    if (!a || !a.dragging) return;
    a.pendingDx += ev.clientX - a.lastX;
    a.lastX = ev.clientX;
    const width = el('match').getBoundingClientRect().width;
    if (!(width >= 1) || a.pendingDx === 0) return;  // the server takes 1..100000 px
    const range = a.t.high - a.t.low;
    const position = Math.min(Math.max(a.position + a.pendingDx / width * range, a.t.low), a.t.high);
    // Held at an end: the moves beyond it are lost, as each of them would be in the lab.
    if (position === a.position) a.pendingDx = 0;
    if (indexAt(a, position) === a.index) return;
    const dx = a.pendingDx;
    a.pendingDx = 0;
    adjustInput({ type: 'drag', dx, width }, ev.timeStamp);
  });
  document.addEventListener('mouseup', () => {
    if (adjust) adjust.dragging = false;
  });

  // ---- keys and buttons -------------------------------------------------------------
  document.addEventListener('keydown', (ev) => {
    if (!state || ev.repeat) return;
    const t = ev.timeStamp;  // when the key went down (performance.now()'s clock)
    const k = ev.key;
    if (['ArrowLeft', 'ArrowRight', 'ArrowUp', 'ArrowDown', 'Enter', ' '].includes(k))
      ev.preventDefault();
    if (state.screen === 'trial') {
      if (state.trial && state.trial.screen === 'adjust')
        return adjustInput({ type: 'key', key: k, shift: ev.shiftKey }, t);
      if (state.trial && state.trial.screen !== 'scales')
        return choiceInput({ type: 'key', key: k }, t);
      return input({ type: 'key', key: k }, t);
    }
    if (k === 'Enter') act('continue', t);
    else if ((k === 'n' || k === 'N') && state.screen === 'consent') act('decline', t);
  });
  el('continue').addEventListener('click', (ev) => act('continue', ev.timeStamp));
  el('decline').addEventListener('click', (ev) => act('decline', ev.timeStamp));
  el('next').addEventListener('click', (ev) => input({ type: 'next' }, ev.timeStamp));
  start();
})();
