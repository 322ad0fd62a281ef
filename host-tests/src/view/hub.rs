//! [`Hub`]: the pages watching one device. Every event goes to each page's queue
//! ([`QUEUE`] events deep); a page that falls that far behind loses the newest events
//! and counts them ([`Hub::dropped`]), and the device is never held up by a slow page.
//! The first page to join holds the controls; the others watch, and the oldest of them
//! takes the controls when the holder leaves.

use std::sync::mpsc::{sync_channel, Receiver, SyncSender, TrySendError};
use std::sync::{Arc, Mutex, MutexGuard};

/// Events a page's queue holds before it drops (2.5 s of telemetry at 100 a second).
pub const QUEUE: usize = 256;

/// One event on the wire: `event: NAME` and its JSON data.
pub type Frame = Arc<str>;

/// A page that joined: its id, its queue, whether it holds the controls then.
pub struct Joined {
    /// Its id (`X-Mccs-Page` on its requests).
    pub id: u64,
    /// Its events.
    pub events: Receiver<Frame>,
}

struct Page {
    id: u64,
    queue: SyncSender<Frame>,
    dropped: u64,
}

#[derive(Default)]
struct Pages {
    next_id: u64,
    pages: Vec<Page>,
    holder: Option<u64>,
    /// The last event of each kind that a new page needs at once (hello, status).
    sticky: Vec<(&'static str, Frame)>,
}

/// The pages watching.
#[derive(Default)]
pub struct Hub {
    pages: Mutex<Pages>,
}

impl Hub {
    fn lock(&self) -> MutexGuard<'_, Pages> {
        self.pages.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// A new page: it holds the controls if no page does. Its queue starts with the
    /// sticky events (the device's facts, its last status).
    pub fn join(&self) -> Joined {
        let mut p = self.lock();
        p.next_id += 1;
        let id = p.next_id;
        let (queue, events) = sync_channel(QUEUE);
        for (_, f) in &p.sticky {
            let _ = queue.try_send(f.clone());
        }
        p.pages.push(Page {
            id,
            queue,
            dropped: 0,
        });
        if p.holder.is_none() {
            p.holder = Some(id);
        }
        Joined { id, events }
    }

    /// The page `id` left: if it held the controls, the oldest page left takes them.
    pub fn leave(&self, id: u64) {
        let mut p = self.lock();
        p.pages.retain(|x| x.id != id);
        if p.holder == Some(id) {
            p.holder = p.pages.first().map(|x| x.id);
        }
    }

    /// Which page holds the controls.
    pub fn holder(&self) -> Option<u64> {
        self.lock().holder
    }

    /// Whether page `id` holds the controls.
    pub fn holds(&self, id: u64) -> bool {
        self.lock().holder == Some(id)
    }

    /// Events page `id` dropped because it fell [`QUEUE`] behind.
    pub fn dropped(&self, id: u64) -> u64 {
        self.lock()
            .pages
            .iter()
            .find(|x| x.id == id)
            .map_or(0, |x| x.dropped)
    }

    /// Pages watching.
    pub fn pages(&self) -> usize {
        self.lock().pages.len()
    }

    /// `frame` to every page (a full queue drops it and counts; a page gone is left).
    pub fn publish(&self, frame: Frame) {
        let mut p = self.lock();
        let mut gone = Vec::new();
        for page in &mut p.pages {
            match page.queue.try_send(frame.clone()) {
                Ok(()) => {}
                Err(TrySendError::Full(_)) => page.dropped += 1,
                Err(TrySendError::Disconnected(_)) => gone.push(page.id),
            }
        }
        drop(p);
        for id in gone {
            self.leave(id);
        }
    }

    /// As [`Hub::publish`], and kept as the `kind` a new page gets first.
    pub fn publish_sticky(&self, kind: &'static str, frame: Frame) {
        {
            let mut p = self.lock();
            p.sticky.retain(|(k, _)| *k != kind);
            p.sticky.push((kind, frame.clone()));
        }
        self.publish(frame);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_page_holds_the_controls_and_the_oldest_left_takes_them_over() {
        let hub = Hub::default();
        let a = hub.join();
        let b = hub.join();
        let c = hub.join();
        assert!(hub.holds(a.id) && !hub.holds(b.id) && !hub.holds(c.id));
        hub.leave(b.id);
        assert!(hub.holds(a.id), "a watcher leaving changes nothing");
        hub.leave(a.id);
        assert!(hub.holds(c.id));
        hub.leave(c.id);
        assert_eq!(hub.holder(), None);
        let d = hub.join();
        assert!(hub.holds(d.id));
    }

    #[test]
    fn a_page_that_falls_behind_drops_and_counts_while_the_others_get_every_event() {
        let hub = Hub::default();
        let slow = hub.join();
        let fast = hub.join();
        let mut got = 0;
        for i in 0..QUEUE + 10 {
            hub.publish(format!("e{i}").into());
            while fast.events.try_recv().is_ok() {
                got += 1;
            }
        }
        assert_eq!(got, QUEUE + 10);
        assert_eq!(hub.dropped(slow.id), 10);
        assert_eq!(hub.dropped(fast.id), 0);
        assert_eq!(slow.events.try_iter().count(), QUEUE);
    }

    #[test]
    fn a_new_page_gets_the_sticky_events_first_the_newest_of_each_kind() {
        let hub = Hub::default();
        hub.publish_sticky("hello", "h1".into());
        hub.publish_sticky("status", "s1".into());
        hub.publish_sticky("hello", "h2".into());
        hub.publish("t".into());
        let p = hub.join();
        let got: Vec<String> = p.events.try_iter().map(|f| f.to_string()).collect();
        assert_eq!(got, ["s1", "h2"]);
    }

    #[test]
    fn a_page_whose_queue_is_gone_is_left_at_the_next_event() {
        let hub = Hub::default();
        let a = hub.join();
        let b = hub.join();
        drop(a.events);
        hub.publish("x".into());
        assert_eq!(hub.pages(), 1);
        assert!(hub.holds(b.id));
    }
}
