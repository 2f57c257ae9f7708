//! The DDS adapter: a participant, a node, the `/joint_states`
//! subscription and the `FollowJointTrajectory` action client around an
//! [`Execution`], polled every couple of milliseconds on the caller's
//! thread (ros2-client's spinner, which delivers discovery events, runs on
//! a thread of its own).
//!
//! The participant advertises and multicasts only on the addresses of
//! [`Ros2Config::networks`] (default 127.0.0.1): RustDDS still binds its
//! unicast sockets to every address, so keeping DDS traffic off a network
//! is the host's business (the tests run in a network namespace with
//! loopback alone).
//!
//! The goal is sent exactly once: after the action's goal and result
//! services have matched (a request sent before that is lost), and after
//! the start check of the execution.

use std::net::IpAddr;
use std::pin::pin;
use std::time::{Duration, Instant};

use futures::FutureExt;
use primo_robot::JointPath;
use primo_robot::execute::{Executed, ExecutionFailed, Executor};
use ros2_client::action::{ActionClient, ActionClientQosPolicies};
use ros2_client::action_msgs::GoalStatusEnum;
use ros2_client::dds::rustdds::DomainParticipantBuilder;
use ros2_client::qos::{Durability, History, WhenFull};
use ros2_client::{
    ActionTypeName, Context, MessageTypeName, Name, Node, NodeName, NodeOptions, QosProfile,
    ServiceMapping, Subscription,
};

use crate::execution::{Command, Execution, ExecutionConfig};
use crate::msgs::{Feedback, FjtResult, Goal, GoalStatus, JointState};
use crate::{Controller, Ros2Error};

/// How primo reaches ROS 2.
#[derive(Debug, Clone, PartialEq)]
pub struct Ros2Config {
    /// The ROS 2 domain ([`crate::domain_from_env`] reads `ROS_DOMAIN_ID`).
    pub domain: u16,
    /// The addresses the participant advertises and multicasts on.
    pub networks: Vec<IpAddr>,
    /// Longest wait for the controller's action server to be discovered.
    pub discovery: Duration,
    /// The execution's tolerances and timeouts.
    pub execution: ExecutionConfig,
}

impl Default for Ros2Config {
    /// Domain 0, 127.0.0.1, 10 s of discovery, the default execution.
    fn default() -> Self {
        Ros2Config {
            domain: 0,
            networks: vec![IpAddr::from([127, 0, 0, 1])],
            discovery: Duration::from_secs(10),
            execution: ExecutionConfig::default(),
        }
    }
}

/// What the adapter is doing, for a progress line.
#[derive(Debug, Clone, PartialEq)]
pub enum Event {
    /// Looking for the action server.
    Discovering,
    /// The action server matched after this long.
    Matched(Duration),
    /// The robot is at the start; the goal is sent.
    GoalSent,
    /// The controller accepted the goal.
    Accepted,
}

/// One goal's run.
#[derive(Debug, Clone, PartialEq)]
pub struct Run {
    /// The joint states since the goal's acceptance, in the chain's order.
    pub executed: Executed,
    /// Feedback messages received.
    pub feedback: usize,
    /// The largest |desired − actual| in the feedback, rad or m.
    pub max_feedback_error: f64,
    /// `Ok` when the goal succeeded with error code 0.
    pub outcome: Result<(), Ros2Error>,
}

/// How often the adapter polls.
const POLL: Duration = Duration::from_millis(2);
/// How long to wait for the controller to answer a cancel.
const CANCEL_WAIT: Duration = Duration::from_secs(1);

fn setup(e: impl std::fmt::Display) -> Ros2Error {
    Ros2Error::Setup(e.to_string())
}

fn comm(e: impl std::fmt::Debug) -> Ros2Error {
    // ros2-client's read and write errors carry no Display.
    let text = format!("{e:?}");
    Ros2Error::Communication(text.split('(').next().unwrap_or(&text).to_string())
}

/// A node with its spinner running, the joint states and the action
/// client.
struct Link {
    node: Node,
    states: Subscription<JointState>,
    action: ActionClient<Goal, FjtResult, Feedback>,
}

impl Link {
    fn new(controller: &Controller, cfg: &Ros2Config) -> Result<Link, Ros2Error> {
        let participant = DomainParticipantBuilder::new(cfg.domain)
            .with_only_networks(cfg.networks.iter().copied())
            .build()
            .map_err(setup)?;
        let context = Context::from_domain_participant(participant).map_err(setup)?;
        let name = NodeName::new("/", &format!("primo_{}", std::process::id())).map_err(setup)?;
        let mut node = context
            .new_node(name, NodeOptions::new().enable_rosout(false))
            .map_err(setup)?;
        let spinner = node.spinner().map_err(setup)?;
        std::thread::Builder::new()
            .name("ros2-spinner".into())
            .spawn(move || futures::executor::block_on(spinner.spin()))
            .map_err(|e| Ros2Error::Setup(format!("cannot start the spinner thread: {e}")))?;
        // rclpy's defaults: best effort for sensor data, reliable services
        // and feedback, a transient-local status.
        let state_qos = QosProfile::subscription_default().history(History::KeepLast { depth: 10 });
        let topic = node
            .create_topic(
                &Name::new("/", "joint_states").map_err(setup)?,
                MessageTypeName::new("sensor_msgs", "JointState"),
                &state_qos,
            )
            .map_err(setup)?;
        let states = node.create_subscription(&topic, None).map_err(setup)?;
        let reliable = QosProfile::publisher_default()
            .reliability_reliable(WhenFull::DEFAULT)
            .durability(Durability::Volatile)
            .history(History::KeepLast { depth: 10 });
        let status = reliable
            .clone()
            .durability(Durability::TransientLocal)
            .history(History::KeepLast { depth: 1 });
        let qos = ActionClientQosPolicies {
            goal_service: reliable.clone(),
            result_service: reliable.clone(),
            cancel_service: reliable.clone(),
            feedback_subscription: reliable,
            status_subscription: status,
        };
        let (namespace, base) = controller.action();
        let action = node
            .create_action_client(
                ServiceMapping::Enhanced,
                &Name::new(namespace, base).map_err(setup)?,
                &ActionTypeName::new("control_msgs", "FollowJointTrajectory"),
                qos,
            )
            .map_err(setup)?;
        Ok(Link {
            node,
            states,
            action,
        })
    }

    /// Waits until the goal and result services have matched a server.
    fn wait_for_server(&self, controller: &Controller, limit: Duration) -> Result<(), Ros2Error> {
        let started = Instant::now();
        let goal = self.action.goal_client().wait_for_service(&self.node);
        let result = self.action.result_client().wait_for_service(&self.node);
        let mut both = pin!(async { futures::join!(goal, result) });
        while started.elapsed() < limit {
            if (&mut both).now_or_never().is_some() {
                return Ok(());
            }
            std::thread::sleep(POLL * 5);
        }
        Err(Ros2Error::NoController {
            action: controller.to_string(),
            waited: started.elapsed(),
        })
    }
}

impl Drop for Link {
    fn drop(&mut self) {
        self.node.stop_spinner();
    }
}

/// Executes `path` on the controller: waits for its action server, checks
/// the robot is at the path's start, sends the goal once and follows it to
/// its end. `Err` when nothing was sent (no controller, DDS setup); a
/// goal that was sent ends in [`Run::outcome`].
pub fn execute(
    controller: &Controller,
    path: &JointPath,
    cfg: &Ros2Config,
    on_event: &mut dyn FnMut(Event),
) -> Result<Run, Ros2Error> {
    let link = Link::new(controller, cfg)?;
    on_event(Event::Discovering);
    let looking = Instant::now();
    link.wait_for_server(controller, cfg.discovery)?;
    on_event(Event::Matched(looking.elapsed()));
    let mut run = Execution::new(path, cfg.execution);
    let clock = Instant::now();
    let now = || clock.elapsed().as_secs_f64();
    let mut goal = None;
    let mut result_request = None;
    let mut cancel = false;
    while run.outcome().is_none() {
        while let Some((state, _)) = link.states.take().map_err(comm)? {
            match run.joint_state(now(), &state) {
                Command::SendGoal(g) => {
                    let (request, id) = link.action.send_goal(*g).map_err(comm)?;
                    goal = Some((request, id));
                    on_event(Event::GoalSent);
                }
                Command::Cancel => cancel = true,
                Command::Wait => {}
            }
        }
        if let Some((request, id)) = goal
            && result_request.is_none()
            && let Some(response) = link.action.receive_goal_response(request).map_err(comm)?
        {
            if response.accepted {
                on_event(Event::Accepted);
                result_request = Some(link.action.request_result(id).map_err(comm)?);
            }
            run.goal_response(now(), response.accepted);
        }
        if let (Some((_, id)), Some(request)) = (goal, result_request) {
            while let Some(feedback) = link.action.receive_feedback(id).map_err(comm)? {
                run.feedback(&feedback);
            }
            if let Some((status, result)) = link.action.receive_result(request).map_err(comm)? {
                run.result(now(), status_of(status), &result);
            }
        }
        if run.tick(now()) == Command::Cancel {
            cancel = true;
        }
        if run.outcome().is_none() {
            std::thread::sleep(POLL);
        }
    }
    if cancel && let Some((_, id)) = goal {
        // Best effort: the outcome is primo's error whatever the answer.
        if let Ok(request) = link.action.cancel_goal(id) {
            let asked = Instant::now();
            while asked.elapsed() < CANCEL_WAIT {
                if let Ok(Some(_)) = link.action.receive_cancel_response(request) {
                    break;
                }
                std::thread::sleep(POLL);
            }
        }
    }
    Ok(Run {
        executed: run.executed().clone(),
        feedback: run.feedback_count(),
        max_feedback_error: run.max_feedback_error(),
        outcome: run.outcome().cloned().unwrap_or(Ok(())),
    })
}

fn status_of(status: GoalStatusEnum) -> GoalStatus {
    match status {
        GoalStatusEnum::Succeeded => GoalStatus::Succeeded,
        GoalStatusEnum::Canceled => GoalStatus::Canceled,
        GoalStatusEnum::Aborted => GoalStatus::Aborted,
        other => GoalStatus::Other(other as i8),
    }
}

/// A robot behind a joint trajectory controller, as an [`Executor`].
#[derive(Debug, Clone)]
pub struct Ros2Robot {
    /// The controller.
    pub controller: Controller,
    /// How to reach it.
    pub config: Ros2Config,
}

impl Executor for Ros2Robot {
    fn execute(&mut self, path: &JointPath) -> Result<Executed, ExecutionFailed> {
        let failed = |why: Ros2Error, executed| ExecutionFailed {
            why: Box::new(why),
            executed,
        };
        match execute(&self.controller, path, &self.config, &mut |_| {}) {
            Ok(Run {
                executed,
                outcome: Ok(()),
                ..
            }) => Ok(executed),
            Ok(Run {
                executed,
                outcome: Err(why),
                ..
            }) => Err(failed(why, executed)),
            Err(why) => Err(failed(why, Executed::default())),
        }
    }
}
