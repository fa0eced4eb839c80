// Which polled state a view may show when it also sends the user's changes (the replay timeline,
// the light panel). A state read while a change was on its way may predate the change and would undo
// it on screen (the replay's loop box ticks itself back on, a light shows "off" after "Turn on"), so
// such a poll is dropped: the change's own reply, or a read after it, shows instead. Of overlapping
// requests only the newest issued is shown, whatever order their replies come back in.

export class StatusOrder {
  constructor() {
    this.issued = 0;          // requests issued, polls and changes together
    this.shown = 0;           // the newest request whose status was shown
    this.changesInFlight = 0;
    this.changesSettled = 0;
  }

  /** A ticket for a poll, or null while a change is in flight (its reply will be shown instead). */
  beginPoll() {
    if (this.changesInFlight) return null;
    return { seq: ++this.issued, poll: true, settled: this.changesSettled };
  }

  /** A ticket for a user's change; call endChange() once its reply or error came back. */
  beginChange() {
    this.changesInFlight++;
    return { seq: ++this.issued, poll: false };
  }

  endChange() {
    this.changesInFlight--;
    this.changesSettled++;
  }

  /** True when the status fetched with `ticket` is the newest to show (and marks it shown). */
  accept(ticket) {
    if (!ticket || ticket.seq < this.shown) return false;
    if (ticket.poll && (this.changesInFlight || this.changesSettled !== ticket.settled)) return false;
    this.shown = ticket.seq;
    return true;
  }
}
